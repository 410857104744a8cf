// `polydg bench` end to end through the binary, as a user runs it: the stability, cutting,
// dynamics, contact, adaptivity and openfoam suites with --quick (under ctest, all but cutting
// from the one `--suite all --quick` run of tests/cli/bench_end_to_end.py; every file written,
// the B4 JSON keys and findings, incremental cuts, B6's energy and period, B7's volume with and
// without corotation, the speed rows, B9's contacts, penetration and energy, the embedding's and
// the queries' figures, both meshers' rows beside OpenFOAM's), the meshing suite finding its
// model in share/polydg beside the binary (build tree and an installation's layout) or in
// --data (its Gmsh comparison skipped there without the bunny), the multigrid suite saying in
// one line how to get the bunny and still running the torus, and an unknown suite refused with
// one line.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/cli/bench/b4_measurements.h"
#include "tests/support/run_polydg.h"

namespace polydg::bench {
namespace {

namespace fs = std::filesystem;

using Result = polydg::testing::CommandResult;

Result run(const std::string& arguments) { return polydg::testing::runPolydg(arguments); }

/// Where `polydg bench --suite SUITE --quick --quiet` wrote its files. Under ctest, the one run
/// of every suite (`--suite all`, the fixture bench_all in tests/CMakeLists.txt) that
/// POLYDG_BENCH_DIR names: the suites are not run twice. Run directly, a fresh run into a
/// scratch folder (`scratch`: the caller removes it), which must succeed and print nothing.
struct SuiteFiles {
  fs::path dir;
  bool scratch = false;
  bool ok = false;
};
SuiteFiles quickSuite(const std::string& suite) {
  if (const char* shared = std::getenv("POLYDG_BENCH_DIR")) return {shared, false, true};
  // Unique per process: two test runs at once must not share (and delete) the folder.
  const fs::path dir = fs::temp_directory_path() /
                       ("polydg_bench_" + suite + "_" + std::to_string(getpid()) + "_out");
  fs::remove_all(dir);
  const Result r = run("bench --suite " + suite + " --quick --quiet --out " + dir.string());
  EXPECT_EQ(r.exitCode, 0) << r.out;
  EXPECT_TRUE(r.out.empty()) << r.out;  // --quiet
  return {dir, true, r.exitCode == 0};
}

TEST(BenchCommand, StabilitySuiteWritesJsonCsvAndPlots) {
  const SuiteFiles files = quickSuite("stability");
  ASSERT_TRUE(files.ok);
  const fs::path& dir = files.dir;
  for (const char* file :
       {"stability.json", "stability.csv", "stability_sliver.svg", "stability_thin_neck.svg",
        "stability_incompressible.svg", "stability_scale.svg"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  std::ifstream in(dir / "stability.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_TRUE(j["cond_method"].get<std::string>().find("Lanczos") != std::string::npos);
  ASSERT_FALSE(j["sliver"].empty());
  // The figures of the quick cases against polydg's (tests/cli/bench/b4_measurements.h, where
  // stability_test.cpp checks the estimates against a dense eigendecomposition): merged slivers
  // (ratios 2e-2, 1e-4 and 1e-12) near the regular grid and within 100x of it (issue 5), the
  // thin neck bounded.
  EXPECT_TRUE(j["summary"]["merged_sliver_within_100x_of_regular"].get<bool>()) << j["summary"];
  for (const nlohmann::json& s : j["sliver"]) {
    ASSERT_TRUE(s.contains("volume_ratio") && s.contains("merged") && s.contains("cond"));
    const double ratio = s["volume_ratio"].get<double>();
    const int p = s["degree"].get<int>();
    if (ratio == 1.0) {
      EXPECT_EQ(s["cond_over_regular"].get<double>(), 1.0) << s.dump();
      EXPECT_TRUE(measured::sameCondition(s["cond"].get<double>(), measured::kRegularCond[p - 1]))
          << s.dump();
    } else if (s["merged"].get<bool>()) {
      EXPECT_TRUE(measured::sameCondition(s["cond_over_regular"].get<double>(),
                                          measured::mergedSliverOverRegular(ratio, p)))
          << s.dump();
    }
  }
  for (const nlohmann::json& s : j["thin_neck"]) {
    ASSERT_TRUE(s["positive_definite"].get<bool>()) << s.dump();
    const int p = s["degree"].get<int>();
    EXPECT_TRUE(measured::sameCondition(s["cond"].get<double>(),
                                        measured::thinNeckCond(s["eps"].get<double>(), p)))
        << s.dump();
  }
  EXPECT_EQ(j["incompressible"].size(), 8u);  // 4 values of nu, p = 1 and 2
  for (const nlohmann::json& s : j["incompressible"])
    EXPECT_TRUE(s.contains("tip") && s.contains("reference") && s.contains("nu"));
  EXPECT_EQ(j["scale"].size(), 12u);  // B1 and B3, 3 scales, 2 offsets
  // Each scaled or translated run keeps its figure up to the round-off its computation allows
  // (measured::scaleChangeBound); the unscaled run at the origin exactly.
  for (const nlohmann::json& s : j["scale"]) {
    const ScaleProblem problem =
        s["problem"].get<std::string>() == "B1" ? ScaleProblem::B1 : ScaleProblem::B3;
    EXPECT_LE(s["change"].get<double>(),
              measured::scaleChangeBound(problem, s["coordinate_resolution"].get<double>(),
                                         s["cond"].get<double>()))
        << s.dump();
  }
  std::ifstream csv(dir / "stability.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find("case"), std::string::npos);
  EXPECT_NE(header.find("volume_ratio"), std::string::npos);
  if (files.scratch) fs::remove_all(dir);
}

TEST(BenchCommand, CuttingSuiteReintegratesOnlyWhatEachCutTouched) {
  const fs::path dir =
      fs::temp_directory_path() / ("polydg_bench_cutting_" + std::to_string(getpid()));
  fs::remove_all(dir);
  const Result r = run("bench --suite cutting --quick --quiet --out " + dir.string());
  ASSERT_EQ(r.exitCode, 0) << r.out;
  for (const char* file : {"cutting.json", "cutting.csv", "cutting.svg"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  std::ifstream in(dir / "cutting.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_GE(j["runs"].size(), 4u);  // 3 cuts with validation none, at least 1 with local
  for (const nlohmann::json& run : j["runs"]) {
    EXPECT_TRUE(run["validation_passed"].get<bool>()) << run.dump();
    EXPECT_GT(run["elements_split"].get<std::size_t>(), 0u) << run.dump();
    // Each split element re-integrates its own faces only: far fewer than the mesh's faces.
    EXPECT_LT(run["faces_reintegrated"].get<std::size_t>(),
              run["faces_total"].get<std::size_t>() / 4)
        << run.dump();
  }
  fs::remove_all(dir);
}

/// B7 of the quick dynamics suite (a quarter turn in 50 steps) per integrator, corotated: the
/// largest volume change and angular momentum change measured 2026-12-04, each bound 2.5 times
/// the figure. Backward Euler's straight steps stretch the spinning cube by (omega dt)^2 =
/// 9.87e-4 per step, which the elastic forces hold at that size; the second-order integrators
/// keep it far smaller, and lose angular momentum to their corrections' tolerance.
struct SpinFigures {
  const char* integrator;
  double volumeChange, angularMomentumChange;
};
constexpr SpinFigures kCorotatedSpin[] = {
    {"euler", 9.87e-4, 2.1e-6}, {"bdf2", 4.4e-5, 1.38e-3}, {"newmark", 1.95e-4, 4.4e-4}};
constexpr double kSpinMargin = 2.5;

TEST(BenchCommand, DynamicsSuiteKeepsEnergyAndVolumeWhereItShould) {
  // B6 over one period of dt = T/200: Newmark (undamped, linear) keeps the energy to round-off
  // (measured 4.6e-11; docs/benchmarks.md, B6: 7e-11 over 10 periods), backward Euler loses
  // some (measured: 0.797 left), every integrator sees two zero crossings, half a period apart.
  constexpr double kNewmarkEnergyChange = 1.5e-10;
  // Of Euler-Bernoulli's 19.58 on the quick, coarser beam: measured +0.66% (backward Euler),
  // +1.8% (BDF2), +1.9% (Newmark); Timoshenko's shear adds about 2%.
  constexpr double kPeriodTolerance = 0.04;
  // B7 over a quarter turn of 50 steps: the linear model's infinitesimal rotation grows the
  // volume by theta^2 = 2.4674 at pi/2 (measured 2.4674 with each integrator), and keeps the
  // angular momentum to round-off (measured 1.3e-12 at most).
  constexpr double kLinearVolumeChange = 2.4674011;
  constexpr double kLinearAngularMomentumChange = 1e-11;
  const SuiteFiles files = quickSuite("dynamics");
  ASSERT_TRUE(files.ok);
  const fs::path& dir = files.dir;
  for (const char* file :
       {"dynamics.json", "dynamics.csv", "dynamics_energy.svg", "dynamics_volume.svg",
        "dynamics_momentum.svg", "dynamics_speed.svg", "dynamics_speed_phases.svg"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  std::ifstream in(dir / "dynamics.json");
  const nlohmann::json j = nlohmann::json::parse(in);

  const nlohmann::json& b6 = j["b6"];
  EXPECT_EQ(b6["steps"].get<int>(), 200);
  ASSERT_EQ(b6["runs"].size(), 3u);
  for (const nlohmann::json& run : b6["runs"]) {
    const std::string integrator = run["integrator"].get<std::string>();
    ASSERT_FALSE(run["period"].is_null()) << run.dump();
    EXPECT_GE(run["zero_crossings"].get<int>(), 2) << run.dump();
    EXPECT_NEAR(run["period_over_euler_bernoulli"].get<double>(), 1.0, kPeriodTolerance)
        << run.dump();
    // No integrator gains energy beyond round-off (backward Euler and BDF2 start at their
    // largest: energy_max is 1 exactly).
    EXPECT_LE(run["energy_max"].get<double>(), 1.0 + kNewmarkEnergyChange) << run.dump();
    if (integrator == "newmark") {
      EXPECT_LT(run["energy_worst_change"].get<double>(), kNewmarkEnergyChange) << run.dump();
    }
    if (integrator == "euler") {  // measured 0.797
      EXPECT_NEAR(run["energy_final"].get<double>(), 0.797, 0.02) << run.dump();
    }
    if (integrator == "bdf2") {  // measured 0.9895
      EXPECT_NEAR(run["energy_final"].get<double>(), 0.9895, 0.005) << run.dump();
    }
  }

  const nlohmann::json& b7 = j["b7"];
  ASSERT_EQ(b7["runs"].size(), 6u);  // 3 integrators, linear and corotational
  for (const nlohmann::json& run : b7["runs"]) {
    const double change = run["volume_change_max"].get<double>();
    const double momentum = run["angular_momentum_change_max"].get<double>();
    if (run["corotational"].get<bool>()) {
      const std::string integrator = run["integrator"].get<std::string>();
      const auto figures =
          std::find_if(std::begin(kCorotatedSpin), std::end(kCorotatedSpin),
                       [&](const SpinFigures& f) { return integrator == f.integrator; });
      ASSERT_NE(figures, std::end(kCorotatedSpin)) << run.dump();
      EXPECT_LT(change, kSpinMargin * figures->volumeChange) << run.dump();
      EXPECT_LT(momentum, kSpinMargin * figures->angularMomentumChange) << run.dump();
    } else {
      EXPECT_NEAR(change, kLinearVolumeChange, 1e-6) << run.dump();
      EXPECT_LT(momentum, kLinearAngularMomentumChange) << run.dump();
    }
    // Free body: no momentum appears beyond the solver's tolerance (measured 3.4e-13 at most
    // with CHOLMOD, 3.6e-12 with CG, the default for corotated steps since 2026-12-04).
    EXPECT_LT(run["momentum_max"].get<double>(), run["corotational"].get<bool>() ? 1e-11 : 1e-12)
        << run.dump();
  }

  const nlohmann::json& speed = j["speed"]["runs"];
  ASSERT_EQ(speed.size(), 3u);  // the smallest grid, 3 integrators
  for (const nlohmann::json& run : speed) {
    EXPECT_EQ(run["grid"], "40x4x4") << run.dump();
    EXPECT_EQ(run["dofs"].get<std::size_t>(), 12u * 40 * 4 * 4) << run.dump();
    EXPECT_GE(run["solves"].get<double>(), 1.0) << run.dump();
    for (const char* phase : {"t_step", "t_rotation", "t_assembly", "t_solve", "steps_per_second"})
      EXPECT_TRUE(run[phase].is_number()) << phase << ": " << run.dump();
  }
  // Cut latency on the 40x4x4 beam (640 elements): a column x = 5.05 splits its 4 x 4 cells, a
  // layer y = 0.53 the 40 x 4 of one row, the diagonal y + z = 1.03 the 7 cells a line crosses
  // in a 4 x 4 section (4 + 4 - 1), 40 times. The phases lie within the latency.
  const nlohmann::json& cuts = j["cut_latency"]["runs"];
  ASSERT_EQ(cuts.size(), 3u);
  const std::size_t split[] = {16, 160, 280};
  for (std::size_t i = 0; i < cuts.size(); ++i) {
    const nlohmann::json& run = cuts[i];
    EXPECT_EQ(run["elements"], 640) << run.dump();
    EXPECT_EQ(run["elements_split"].get<std::size_t>(), split[i]) << run.dump();
    double phases = 0.0;
    for (const char* phase : {"t_cut", "t_solver", "t_transfer", "t_next_step"}) {
      EXPECT_GT(run[phase].get<double>(), 0.0) << phase << ": " << run.dump();
      phases += run[phase].get<double>();
    }
    EXPECT_LE(phases, run["t_latency"].get<double>()) << run.dump();
    EXPECT_LE(run["t_check"].get<double>(), run["t_cut"].get<double>()) << run.dump();
    // The new solver computed the blocks of the pieces and their neighbours only.
    EXPECT_LT(run["solver_elements"].get<std::size_t>(), 640 + split[i]) << run.dump();
  }
  // The column's 32 pieces and the 2 x 16 cells beside them.
  EXPECT_EQ(cuts[0]["solver_elements"], 64) << cuts[0].dump();
  std::ifstream csv(dir / "dynamics.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* column : {"part", "integrator", "energy", "volume_change", "t_rotation"})
    EXPECT_NE(header.find(column), std::string::npos) << column;
  if (files.scratch) fs::remove_all(dir);
}

TEST(BenchCommand, ContactSuiteDetectsContactAndKeepsEnergyFromGrowing) {
  // The quick drops (0.4 s) reach the ground and the bowl at t = 0.356 (mass damping slows the
  // fall): about 12 steps in contact, the sphere still moving. Measured: penetration 1.3e-3 at
  // the end (below B9's limit already); the total energy falls at every step (damping).
  constexpr double kPenetrationLimit = 0.005;  // B9: 1% of the radius
  constexpr double kEnergyRoundoff = 1e-9;     // of weight x radius (the suite's allowance)
  const SuiteFiles files = quickSuite("contact");
  ASSERT_TRUE(files.ok);
  const fs::path& dir = files.dir;
  for (const char* file : {"contact.json", "contact.csv", "contact_step_time.svg",
                           "contact_penetration.svg", "contact_energy.svg"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  std::ifstream in(dir / "contact.json");
  const nlohmann::json j = nlohmann::json::parse(in);

  const nlohmann::json& embedding = j["embedding"];
  EXPECT_GT(embedding["elements"].get<std::size_t>(), 0u);
  ASSERT_EQ(embedding["runs"].size(), 2u);  // p = 1, 2
  for (const nlohmann::json& run : embedding["runs"]) {
    EXPECT_EQ(run["points"], embedding["vertices"]) << run.dump();
    EXPECT_EQ(run["outside"].get<std::size_t>(), 0u) << run.dump();  // on the sliced surface
    // Each point reads at least one element's functions.
    EXPECT_GE(run["weight_nonzeros"].get<std::size_t>(),
              run["points"].get<std::size_t>() * (run["degree"] == 1 ? 4u : 10u))
        << run.dump();
    EXPECT_GT(run["update_seconds"].get<double>(), 0.0) << run.dump();
  }

  ASSERT_EQ(j["queries"]["runs"].size(), 2u);  // the ground, the bowl
  for (const nlohmann::json& run : j["queries"]["runs"]) {
    EXPECT_GT(run["query_seconds"].get<double>(), 0.0) << run.dump();
    EXPECT_GT(run["inside"].get<std::size_t>(), 0u) << run.dump();
    if (run["obstacle"] == "bowl") {
      EXPECT_GT(run["active_voxels"].get<std::size_t>(), 0u) << run.dump();
      EXPECT_GT(run["checked_points"].get<std::size_t>(), 0u) << run.dump();
      // Against the spheres: the faceting of the bowl and a voxel's interpolation at most.
      EXPECT_LT(run["max_distance_error"].get<double>(),
                run["facet_sag"].get<double>() + run["voxel"].get<double>())
          << run.dump();
    }
  }

  const nlohmann::json& step = j["step"];
  EXPECT_GT(step["contact_steps"].get<int>(), 0) << step.dump();
  EXPECT_EQ(step["contact_points"], embedding["vertices"]) << step.dump();
  for (const char* key :
       {"t_step_contact", "t_collision_contact", "collision_over_step", "update_over_step"})
    EXPECT_GT(step[key].get<double>(), 0.0) << key << ": " << step.dump();

  ASSERT_EQ(j["b9"]["runs"].size(), 2u);  // the ground, the bowl
  for (const nlohmann::json& run : j["b9"]["runs"]) {
    EXPECT_TRUE(run["energies_finite"].get<bool>()) << run.dump();
    EXPECT_GT(run["contact_steps"].get<int>(), 0) << run.dump();
    EXPECT_GT(run["final_contacts"].get<std::size_t>(), 0u) << run.dump();
    EXPECT_GT(run["final_penetration"].get<double>(), 0.0) << run.dump();
    EXPECT_LT(run["final_penetration"].get<double>(), kPenetrationLimit) << run.dump();
    EXPECT_LE(run["max_energy_growth"].get<double>(),
              kEnergyRoundoff * run["energy_scale"].get<double>())
        << run.dump();
    EXPECT_TRUE(run["energy_never_grows"].get<bool>()) << run.dump();
  }
  std::ifstream csv(dir / "contact.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* column :
       {"part", "obstacle", "deepest", "kinetic", "elastic", "gravity", "contact_energy", "total",
        "com_z", "weight_nonzeros", "query_seconds"})
    EXPECT_NE(header.find(column), std::string::npos) << column;
  if (files.scratch) fs::remove_all(dir);
}

TEST(BenchCommand, SfemSuiteShowsThePapersFindings) {
  // Quick sizes: the pressure cantilever on 625 tets against IP p = 3 on 4^3 hexahedra, the
  // falling beam on 360 tets for 0.5 s. Zhang et al.'s findings: the smoothed strain is
  // softer and more accurate than linear FEM at every distortion, and less sensitive to it;
  // warping keeps the falling beam's volume, linear forces inflate it.
  const SuiteFiles files = quickSuite("sfem");
  ASSERT_TRUE(files.ok);
  for (const char* file : {"sfem.json", "sfem.csv", "sfem_pressure.svg", "sfem_speed.svg"})
    EXPECT_TRUE(fs::exists(files.dir / file)) << file;
  std::ifstream in(files.dir / "sfem.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::map<std::string, std::map<double, double>> error, energy;
  for (const auto& run : j["pressure"]["runs"]) {
    error[run["method"]][run["alpha"]] = run["energy_error"].get<double>();
    energy[run["method"]][run["alpha"]] = run["energy"].get<double>();
  }
  ASSERT_EQ(error["L-FEM"].size(), 5u);
  const double reference = j["pressure"]["reference"]["energy"].get<double>();
  for (const auto& [alpha, e] : error["L-FEM"]) {
    EXPECT_LT(error["LFS-FEM"][alpha], e) << "alpha " << alpha;
    EXPECT_GT(energy["LFS-FEM"][alpha], energy["L-FEM"][alpha]) << "alpha " << alpha;
    EXPECT_LT(energy["L-FEM"][alpha], reference) << "alpha " << alpha;  // FEM is too stiff
  }
  EXPECT_LT(error["LFS-FEM"][0.4] - error["LFS-FEM"][0.0],
            error["L-FEM"][0.4] - error["L-FEM"][0.0]);
  // Speed against error (quick: n = 4, 8 for the tets, 2, 4 for IP p = 1): the error falls
  // with h, at second order at least (a factor above 2.5 from one h to its half).
  std::map<std::string, std::map<int, double>> l2;
  for (const auto& run : j["speed_against_error"])
    l2[run["method"]][run["n"].get<int>()] = run["l2_error"].get<double>();
  for (const char* method : {"FEM", "FS-FEM", "IP p=1"}) {
    ASSERT_EQ(l2[method].size(), 2u) << method;
    EXPECT_GT(l2[method].begin()->second, 2.5 * l2[method].rbegin()->second) << method;
  }
  std::map<std::string, double> volume;
  for (const auto& run : j["rotation"]) volume[run["method"]] = run["largest_volume_change"];
  for (const char* linear : {"L-FEM", "LFS-FEM"})
    for (const char* warped : {"C-FEM", "CS-FEM"})
      EXPECT_GT(volume[linear], 10 * volume[warped]) << linear << " against " << warped;
  // Time per step: each size's C-FEM and CS-FEM rows, then DG at about the same DOFs (an
  // n x m x m grid at 12 DOFs an element: within 10% of the tets' 3 per node).
  const nlohmann::json& steps = j["time_per_step"];
  ASSERT_EQ(steps.size(), 6u);  // quick: k = 1, 2
  for (std::size_t i = 0; i < steps.size(); i += 3) {
    EXPECT_EQ(steps[i]["method"], "C-FEM");
    EXPECT_EQ(steps[i + 1]["method"], "CS-FEM");
    ASSERT_EQ(steps[i + 2]["method"], "IP p = 1");
    const double tetDofs = 3.0 * steps[i]["nodes"].get<double>();
    const double ratio = steps[i + 2]["dofs"].get<double>() / tetDofs;
    EXPECT_NEAR(ratio, 1.0, 0.1) << "size " << i / 3 + 1;
    EXPECT_GT(steps[i + 2]["seconds_per_step"].get<double>(), 0.0);
  }
}

TEST(BenchCommand, OpenfoamSuiteSetsBothMeshersSideBySide) {
  // Quick: the torus at 12 cells, one round. polydg's boundary is the surface exactly and its
  // volume the surface's; snappyHexMesh's is snapped to within a cell, and checkMesh gives both
  // a verdict. Without OpenFOAM the suite says so in one line and writes no rows and no plots.
  const SuiteFiles files = quickSuite("openfoam");
  ASSERT_TRUE(files.ok);
  for (const char* file : {"openfoam.json", "openfoam.csv"})
    EXPECT_TRUE(fs::exists(files.dir / file)) << file;
  std::ifstream in(files.dir / "openfoam.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  if (j.contains("skipped")) {
    EXPECT_NE(j["skipped"].get<std::string>().find("not installed"), std::string::npos) << j;
    EXPECT_FALSE(j.contains("rows"));
    if (files.scratch) fs::remove_all(files.dir);
    return;
  }
  for (const char* file :
       {"openfoam_time.svg", "openfoam_volume_error.svg", "openfoam_distance.svg"})
    EXPECT_TRUE(fs::exists(files.dir / file)) << file;
  ASSERT_EQ(j["rows"].size(), 2u) << j;
  const nlohmann::json &polydg = j["rows"][0], &snappy = j["rows"][1];
  ASSERT_EQ(polydg["mesher"], "polydg");
  ASSERT_EQ(snappy["mesher"], "snappyHexMesh");
  const nlohmann::json& setup = j["snappy_setup"][0];
  EXPECT_EQ(setup["block_cells"], nlohmann::json({14, 14, 6}));  // polydg's 12 x 12 x 4, + 2
  EXPECT_EQ(setup["surface_level"], 0);
  for (const nlohmann::json& row : {polydg, snappy}) {
    ASSERT_FALSE(row.contains("error")) << row;
    EXPECT_EQ(row["model"], "torus");
    EXPECT_EQ(row["n"], 12);
    EXPECT_GT(row["cells"].get<std::size_t>(), 0u) << row;
    EXPECT_NE(row["checkmesh_verdict"], "no verdict") << row;
    EXPECT_GT(row["wall_seconds"].get<double>(), 0.0);
    EXPECT_GT(row["max_skewness"].get<double>(), 0.0);
  }
  EXPECT_LT(polydg["max_boundary_distance_rel"].get<double>(), 1e-14) << polydg;
  EXPECT_LT(polydg["volume_rel_error"].get<double>(), 1e-12) << polydg;
  EXPECT_GT(snappy["max_boundary_distance"].get<double>(), 1e-6) << snappy;
  EXPECT_LT(snappy["max_boundary_distance"].get<double>(), setup["cell_size"].get<double>());
  EXPECT_LT(snappy["volume_rel_error"].get<double>(), 0.2) << snappy;
  std::ifstream csv(files.dir / "openfoam.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* column : {"model", "n", "mesher", "wall_seconds", "cells", "volume_rel_error",
                             "max_boundary_distance_rel", "checkmesh_verdict",
                             "checkmesh_failed_checks", "max_non_orthogonality"})
    EXPECT_NE(header.find(column), std::string::npos) << column;
  if (files.scratch) fs::remove_all(files.dir);
}

TEST(BenchCommand, AdaptivitySuiteRefinesWhereItShould) {
  // Quick sizes: B11 at tau = 0.5 (2 rounds), B13 at 32 cells of a 5,120-triangle sphere, B12 on
  // uniform 4^3 and 8^3 and 2 adaptive rounds from 4^3 for p = 1-3, the reference checks at
  // p = 1.
  const SuiteFiles files = quickSuite("adaptivity");
  ASSERT_TRUE(files.ok);
  const fs::path& dir = files.dir;
  for (const char* file : {"adaptivity.json", "adaptivity.csv", "adaptivity_b12.svg"})
    EXPECT_TRUE(fs::exists(dir / file)) << file;
  std::ifstream in(dir / "adaptivity.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  std::size_t octants = 0, halves = 0;
  for (const auto& b11 : j["B11"]) {
    const std::size_t n = b11["elements"].get<std::size_t>();
    EXPECT_GT(n, 36u) << b11.dump();
    (b11["split"] == "octants" ? octants : halves) = n;
  }
  EXPECT_GT(octants, halves);
  const auto& b13 = j["B13"];
  ASSERT_EQ(b13.size(), 2u);
  EXPECT_TRUE(b13[0]["passed"].get<bool>() && b13[1]["passed"].get<bool>());
  EXPECT_LT(b13[1]["elements"].get<std::size_t>(), b13[0]["elements"].get<std::size_t>());
  EXPECT_NEAR(b13[1]["volume"].get<double>(), b13[0]["volume"].get<double>(),
              1e-10 * b13[0]["volume"].get<double>());
  // B12 for p = 1-3: the estimate within the specification's [0.3, 3] of the true error on
  // every mesh, uniform and adapted; adaptive rounds lower the error. The estimator against
  // reference solves (L-prism and torus, p = 1 in the quick run) likewise.
  auto inWindow = [](const nlohmann::json& run) {
    const double effectivity = run["effectivity"].get<double>();
    EXPECT_GE(effectivity, 0.3) << run.dump();
    EXPECT_LE(effectivity, 3.0) << run.dump();
  };
  ASSERT_EQ(j["B12"].size(), 3u);
  for (const auto& degree : j["B12"]) {
    for (const auto& run : degree["uniform"]) inWindow(run);
    const auto& adaptive = degree["adaptive"];
    ASSERT_GE(adaptive.size(), 2u) << degree.dump();
    for (const auto& round : adaptive) inWindow(round);
    EXPECT_LT(adaptive.back()["l2_error"].get<double>(),
              adaptive.front()["l2_error"].get<double>());
  }
  ASSERT_EQ(j["estimator_references"].size(), 2u);
  for (const auto& run : j["estimator_references"]) inWindow(run);
  if (files.scratch) fs::remove_all(dir);
}

TEST(BenchCommand, UnknownSuiteIsRefusedWithOneLine) {
  const Result r = run("bench --suite nonsense --out " +
                       (fs::temp_directory_path() / "polydg_bench_unknown").string());
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_FALSE(fs::exists(fs::temp_directory_path() / "polydg_bench_unknown"));
}

/// A scratch folder per test (polydg::testing::CommandTest).
class BenchData : public polydg::testing::CommandTest {};

TEST_F(BenchData, MeshingSuiteFindsItsModelBesideTheBinaryFromAnyFolder) {
  // Run from the scratch folder: no path relative to the working directory can help.
  const Result r = polydg::testing::runShell("cd '" + dir_.string() + "' && " + POLYDG_BINARY +
                                             " bench --suite meshing --quick --quiet --out out");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const nlohmann::json j = readJson("out/meshing.json");
  // torus.obj at 8 and 16 cells, then the Gmsh comparison: skipped without the bunny, which
  // the build's share/polydg does not hold.
  ASSERT_EQ(j.size(), 3u) << j;
  for (int i = 0; i < 2; ++i) {
    const nlohmann::json& row = j[i];
    EXPECT_EQ(row["model"], "torus.obj");
    EXPECT_TRUE(row["valid"].get<bool>()) << row.dump();
    EXPECT_TRUE(row["dg_passed"].get<bool>()) << row.dump();
  }
  EXPECT_EQ(j[2]["comparison"], "gmsh HXT");
  EXPECT_NE(j[2]["skipped"].get<std::string>().find("bunny.off not found"), std::string::npos)
      << j[2];
}

TEST_F(BenchData, MultigridSuiteSaysHowToGetTheBunnyAndRunsTheTorus) {
  // testdata/ holds torus.obj but not models/bunny.off.
  const Result r = run(std::string("bench --suite multigrid --quick --data ") +
                       POLYDG_TESTDATA_DIR + " --out " + path("out"));
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const std::size_t note = r.out.find("bunny.off not found: run scripts/get-models.sh");
  ASSERT_NE(note, std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("bunny", r.out.find('\n', note)), std::string::npos) << r.out;
  const nlohmann::json j = readJson("out/multigrid.json");
  EXPECT_TRUE(j.contains("missing"));
  ASSERT_EQ(j["rows"].size(), 4u);  // the torus sliced and cut, p = 1 and 2
  for (const nlohmann::json& row : j["rows"]) {
    EXPECT_EQ(row["model"], "torus");
    EXPECT_GT(row["iterations"].get<int>(), 0) << row.dump();
    EXPECT_GT(row["cube_iterations"].get<int>(), 0) << row.dump();
    EXPECT_GT(row["dofs"].get<std::size_t>(), 0u) << row.dump();
  }
  EXPECT_LT(j["rows"][2]["elements"].get<std::size_t>(),
            j["rows"][0]["elements"].get<std::size_t>())
      << "the plane cut removes a part";
  EXPECT_TRUE(fs::exists(dir_ / "out" / "multigrid.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "multigrid.svg"));
}

TEST_F(BenchData, CopiedBinaryLooksInItsOwnShareFolderOrInData) {
  // An installation's layout, PREFIX/bin/polydg beside PREFIX/share/polydg/.
  fs::create_directories(dir_ / "bin");
  fs::copy_file(POLYDG_BINARY, dir_ / "bin" / "polydg");
  const std::string polydg = (dir_ / "bin" / "polydg").string() + " bench --suite meshing --quick";
  const std::string expected = (dir_ / "share" / "polydg" / "torus.obj").string();
  const Result missing = polydg::testing::runShell(polydg + " --out " + path("a"));
  EXPECT_EQ(missing.exitCode, 2) << missing.out;
  EXPECT_NE(missing.out.find(expected + " not found"), std::string::npos) << missing.out;
  EXPECT_EQ(std::count(missing.out.begin(), missing.out.end(), '\n'), 1) << missing.out;

  const Result data = polydg::testing::runShell(polydg + " --quiet --data " + POLYDG_TESTDATA_DIR +
                                                " --out " + path("b"));
  EXPECT_EQ(data.exitCode, 0) << data.out;
  EXPECT_TRUE(fs::exists(dir_ / "b" / "meshing.json"));

  fs::create_directories(dir_ / "share" / "polydg");
  fs::copy_file(polydg::testing::testData("torus.obj"), expected);
  const Result installed = polydg::testing::runShell(polydg + " --quiet --out " + path("c"));
  EXPECT_EQ(installed.exitCode, 0) << installed.out;
  EXPECT_TRUE(fs::exists(dir_ / "c" / "meshing.json"));
}

}  // namespace
}  // namespace polydg::bench
