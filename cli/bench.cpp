// polydg bench: the benchmark suites of shared/BENCHMARKS.md, each written as DIR/NAME.json,
// DIR/NAME.csv and one or more plots DIR/NAME*.svg.
//
// Sample runs:
//   polydg bench --suite all --out bench/          (every suite; about four minutes on 2 cores)
//   polydg bench --suite stability --out bench/    (B4: conditioning, locking, scale)
//   polydg bench --suite stability --out b/ --quick   (reduced sizes, as the tests run it)
//
// Suites and sizes:
//   accuracy   B1 with IP and BZ, degrees 1-3, hex grids (p = 1: n = 4, 8, 16, 24; p = 2: 2, 4,
//              8, 12; p = 3: 2, 3, 4, 6, 8) and sliced cubes (p = 1: 4, 8, 12; p = 2: 2, 4, 8;
//              p = 3: 2, 4, 6). Plot: L2 error against integration + assembly + solve time
//              (everything from the mesh to the solution).
//   table41    B2 (10^3 hexahedra) with BZ and IP, degrees 1 and 2, beside the thesis's Table 4.1.
//              Each case runs five times; the fastest run (by total time) is reported.
//   stability  B4: sliver (volume ratio 1 .. 1e-12 by factors of 10, and 0.05 and 0.02 near
//              the merge threshold; merged or not, p = 1, 2), thin neck (eps
//              1e-1 .. 1e-9), near-incompressible cantilever (nu 0.3 .. 0.4999, p = 1, 2),
//              scale and position (B1 and B3 scaled by 1e-6, 1, 1e6, offsets 0 and
//              (1e6, -1e6, 1e6), p = 2).
//   cutting    plane cuts of growing size on a 47^3 hex grid (103,823 elements): time per cut
//              against elements split, validation none and local, beside a full moment rebuild.
//   meshing    the meshing pipeline and its validation (geometric, DG checks) for the bundled
//              testdata/torus.obj and the generated sphere and torus knot at 16 .. 128 cells.
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/csv.h"
#include "cli/plot.h"
#include "polydg/cut/cut.h"
#include "polydg/mesh/meshing.h"
#include "polydg/mesh/primitives.h"
#include "polydg/mesh/surface_io.h"
#include "polydg/model/files.h"
#include "polydg/model/names.h"
#include "polydg/physics/benchmarks.h"
#include "polydg/physics/stability.h"
#include "polydg/util/error.h"

#ifndef POLYDG_TESTDATA_DIR
#define POLYDG_TESTDATA_DIR "testdata"
#endif

namespace polydg::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

struct BenchOptions {
  std::string suite;
  std::string out;
  bool skipSliced = false;
  bool quick = false;
  std::string dataDir = POLYDG_TESTDATA_DIR;
};

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}
std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// A plot and the file it goes to.
struct NamedPlot {
  std::string file;
  Plot plot;
};

/// What a suite writes: NAME.json, NAME.csv (from `rows`) and its plots.
struct SuiteOutput {
  std::string name;
  nlohmann::json json;
  nlohmann::json rows = nlohmann::json::array();
  std::vector<NamedPlot> plots;
};

void writeSuite(const fs::path& dir, const SuiteOutput& s, bool quiet) {
  writeJsonFile(dir / (s.name + ".json"), s.json);
  const std::string csv = toCsv(s.rows);
  writeFileAtomically(dir / (s.name + ".csv"), [&](std::ostream& os) { os << csv; });
  for (const NamedPlot& p : s.plots) {
    const std::string svg = renderSvg(p.plot);
    writeFileAtomically(dir / p.file, [&](std::ostream& os) { os << svg; });
  }
  if (!quiet) {
    std::cout << "wrote " << (dir / (s.name + ".json")).string() << ", " << s.name << ".csv";
    for (const NamedPlot& p : s.plots) std::cout << ", " << p.file;
    std::cout << std::endl;
  }
}

/// A series keyed by label, filled in run order.
class SeriesSet {
 public:
  void add(const std::string& key, double x, double y) {
    auto [it, fresh] = index_.emplace(key, series_.size());
    if (fresh) series_.push_back({key, {}, {}});
    series_[it->second].x.push_back(x);
    series_[it->second].y.push_back(y);
  }
  std::vector<PlotSeries>& series() { return series_; }

 private:
  std::map<std::string, std::size_t> index_;
  std::vector<PlotSeries> series_;
};

// --- accuracy and table41 ------------------------------------------------------------------

nlohmann::json runJson(const BenchmarkRun& r) {
  return {{"method", toString(r.method)},
          {"degree", r.degree},
          {"mesh", r.mesh == BenchmarkMesh::Hex ? "hex" : "sliced"},
          {"n", r.n},
          {"elements", r.report.elements},
          {"dofs", r.report.dofs},
          {"nonzeros", r.report.nonzeros},
          {"sparsity", r.sparsity},
          {"t_integrate", r.report.integrateSeconds},
          {"t_assemble", r.report.assembleSeconds},
          {"t_solve", r.report.solveSeconds},
          {"l2_error", r.l2Error},
          {"h1_error", r.h1Error},
          {"eta", r.report.eta},
          {"solver", toString(r.report.solver.used)},
          {"iterations", r.report.solver.iterations},
          {"residual", r.report.solver.residual}};
}

/// Grid sizes of the accuracy suite per degree (at least three each; two with --quick).
std::vector<int> accuracySizes(int degree, BenchmarkMesh mesh, bool quick) {
  if (quick) return degree == 1 ? std::vector<int>{2, 4} : std::vector<int>{1, 2};
  if (mesh == BenchmarkMesh::Sliced) {
    switch (degree) {
      case 1: return {4, 8, 12};
      case 2: return {2, 4, 8};
      default: return {2, 4, 6};
    }
  }
  switch (degree) {
    case 1: return {4, 8, 16, 24};
    case 2: return {2, 4, 8, 12};
    default: return {2, 3, 4, 6, 8};
  }
}

void printRun(const BenchmarkRun& r) {
  std::cout << toString(r.method) << " p=" << r.degree << ' '
            << (r.mesh == BenchmarkMesh::Hex ? "hex" : "sliced") << " n=" << r.n << ": "
            << r.report.dofs << " DOFs, integrate " << r.report.integrateSeconds << " s, assemble "
            << r.report.assembleSeconds << " s, solve " << r.report.solveSeconds << " s";
  if (r.l2Error > 0) std::cout << ", L2 " << r.l2Error;
  std::cout << std::endl;
}

/// B1's reference point (BENCHMARKS.md): continuous P2 tetrahedra with algebraic multigrid.
PlotSeries referenceLibrarySeries() {
  return {"reference: FEM P2 tets + AMG", {0.5, 8.0}, {9.4e-6, 1.2e-6}};
}

SuiteOutput accuracySuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"accuracy", nlohmann::json::array(), nlohmann::json::array(), {}};
  std::vector<BenchmarkMesh> meshes{BenchmarkMesh::Hex};
  if (!o.skipSliced) meshes.push_back(BenchmarkMesh::Sliced);
  const int maxDegree = o.quick ? 2 : 3;
  SeriesSet l2;
  std::vector<std::string> labels;  // series labels with their last rates, in series order
  for (BenchmarkMesh mesh : meshes)
    for (Method method : {Method::IP, Method::BZ})
      for (int p = 1; p <= maxDegree; ++p) {
        const std::string key = upper(toString(method)) + " p=" + std::to_string(p) + " " +
                                (mesh == BenchmarkMesh::Hex ? "hex" : "sliced");
        std::optional<BenchmarkRun> previous;
        double lastRate = std::numeric_limits<double>::quiet_NaN();
        for (int n : accuracySizes(p, mesh, o.quick)) {
          StaticOptions so;
          so.discretization.method = method;
          so.discretization.basis.degree = p;
          const BenchmarkRun r = runBenchmarkB1(n, so, mesh);
          if (!quiet) printRun(r);
          nlohmann::json j = runJson(r);
          if (previous) {
            const double dh = std::log(static_cast<double>(r.n) / previous->n);
            lastRate = std::log(previous->l2Error / r.l2Error) / dh;
            j["l2_rate"] = lastRate;
            j["h1_rate"] = std::log(previous->h1Error / r.h1Error) / dh;
          }
          s.json.push_back(j);
          s.rows.push_back(j);
          l2.add(key, r.report.integrateSeconds + r.report.assembleSeconds + r.report.solveSeconds,
                 r.l2Error);
          previous = r;
        }
        labels.push_back(key + ", L2 rate " + shortNumber(lastRate));
      }
  std::vector<PlotSeries> all = l2.series();
  for (std::size_t i = 0; i < all.size(); ++i) all[i].label = labels[i];
  for (BenchmarkMesh mesh : meshes) {
    const std::string kind = mesh == BenchmarkMesh::Hex ? "hex" : "sliced";
    std::vector<PlotSeries> series;
    for (const PlotSeries& p : all)
      if (p.label.find(" " + kind + ",") != std::string::npos) series.push_back(p);
    series.push_back(referenceLibrarySeries());
    s.plots.push_back({"accuracy_" + kind + ".svg",
                       {"B1 accuracy on " + kind + " meshes: L2 error against time",
                        {"wall time, integration + assembly + solve [s]", AxisScale::Log},
                        {"L2 error of u (legend: rate over the last halving of h)", AxisScale::Log},
                        series}});
  }
  return s;
}

/// Runs of each B2 case; the table reports the fastest.
constexpr int kB2Repeats = 5;

SuiteOutput table41Suite(bool quiet) {
  SuiteOutput s{"table41", nlohmann::json::array(), nlohmann::json::array(), {}};
  std::vector<PlotSeries> series;
  for (Method method : {Method::BZ, Method::IP})
    for (int p = 1; p <= 2; ++p) {
      StaticOptions so;
      so.discretization.method = method;
      so.discretization.basis.degree = p;
      // The fastest of kB2Repeats runs (by total time): the first run of a process also pays
      // for starting TBB's threads and faulting in fresh memory, and the machine may be busy.
      BenchmarkRun r, first;
      double best = std::numeric_limits<double>::infinity();
      for (int repeat = 0; repeat < kB2Repeats; ++repeat) {
        BenchmarkRun candidate = runBenchmarkB2(so);
        if (repeat == 0) first = candidate;
        const double total = candidate.report.integrateSeconds + candidate.report.assembleSeconds +
                             candidate.report.solveSeconds;
        if (total < best) {
          best = total;
          r = std::move(candidate);
        }
      }
      if (!quiet) printRun(r);
      const nlohmann::json row = runJson(r);  // the CSV row; the JSON adds the nested parts
      nlohmann::json j = row;
      j["runs"] = kB2Repeats;
      // The first run, for comparison: it also starts TBB's threads and faults in fresh memory.
      j["first_run"] = {{"t_integrate", first.report.integrateSeconds},
                        {"t_assemble", first.report.assembleSeconds},
                        {"t_solve", first.report.solveSeconds}};
      s.json.push_back(j);
      s.rows.push_back(row);
      series.push_back(
          {"polydg " + upper(toString(method)) + (p == 1 ? " lin" : " quad"),
           {1, 2, 3},
           {r.report.integrateSeconds, r.report.assembleSeconds, r.report.solveSeconds}});
    }
  // The thesis's Table 4.1 (Core2 Duo 2.4 GHz, 2008), ms.
  const std::vector<std::pair<std::string, std::array<double, 3>>> thesis{
      {"thesis BZ lin", {532, 22, 656}},
      {"thesis IP lin", {1437, 87, 734}},
      {"thesis BZ quad", {3062, 152, 7797}},
      {"thesis IP quad", {8344, 621, 8484}}};
  for (const auto& [label, ms] : thesis)
    series.push_back({label, {1, 2, 3}, {ms[0] / 1e3, ms[1] / 1e3, ms[2] / 1e3}});
  s.plots.push_back({"table41.svg",
                     {"B2 (Table 4.1): time per phase, polydg today vs the thesis",
                      {"phase", AxisScale::Linear, {"integration", "assembly", "solve"}},
                      {"wall time [s]", AxisScale::Log},
                      series}});
  return s;
}

// --- stability -----------------------------------------------------------------------------

nlohmann::json conditionJson(const StabilityConditionRun& r) {
  const ConditionEstimate& c = r.estimate;
  return {{"degree", r.degree},
          {"elements", r.elements},
          {"dofs", r.dofs},
          {"eta", r.eta},
          {"cond", c.positiveDefinite ? nlohmann::json(c.cond) : nlohmann::json(nullptr)},
          {"lambda_min", c.lambdaMin},
          {"lambda_max", c.lambdaMax},
          {"positive_definite", c.positiveDefinite},
          {"cond_jacobi", r.jacobiEstimate.positiveDefinite ? nlohmann::json(r.jacobiEstimate.cond)
                                                            : nlohmann::json(nullptr)},
          // Beyond 1/eps the smallest eigenvalue is below the round-off of K's entries: the
          // estimate says "singular to double precision", not a precise number.
          {"beyond_double_precision", c.cond * std::numeric_limits<double>::epsilon() > 1.0}};
}

SuiteOutput stabilitySuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"stability", nlohmann::json::object(), nlohmann::json::array(), {}};
  s.json["cond_method"] = kConditionMethod;
  s.json["setup"] = {{"sliver",
                      "3x3x3 unit cubes, centre cell split at x = 1 + volume_ratio; IP, E = 1, "
                      "nu = 0.3, u = 0 weakly on the whole boundary; merged: mergeSlivers with "
                      "threshold 0.01 of a cell (the meshing default)"},
                     {"thin_neck",
                      "one element: blocks [0,1]^3 and [2,3]x[0,1]^2 joined by the neck "
                      "[1,2]x[0,eps]x[0,1]; IP, clamped on x = 0"},
                     {"incompressible",
                      "B3 on the locking-test meshes: p = 1 160x4x8 with penalty doubling, "
                      "p = 2 40x4x4; reference = Euler-Bernoulli + Timoshenko shear at nu"},
                     {"scale",
                      "B1 (n = 4 hex, p = 2; rel_error = L2 error / L2 norm of u) and B3 (40x4x4, "
                      "p = 2; rel_error = tip / (scale * unscaled tip) - 1), lengths times scale, "
                      "translated by offset"}};
  const double eps = std::numeric_limits<double>::epsilon();
  auto log = [&](const std::string& line) {
    if (!quiet) std::cout << line << std::endl;
  };

  // Sliver.
  const std::vector<double> ratios =
      o.quick ? std::vector<double>{1, 1e-4, 1e-12}
              : std::vector<double>{1,    1e-1, 5e-2, 2e-2, 1e-2,  1e-3,  1e-4, 1e-5,
                                    1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
  nlohmann::json sliver = nlohmann::json::array(), regular = nlohmann::json::object();
  SeriesSet sliverPlot;
  bool mergedWithin100 = true;
  nlohmann::json mergedBeyond100 = nlohmann::json::array();  // {degree, volume_ratio}
  for (int p : {1, 2}) {
    const double regularCond = runSliverCase(1.0, false, p).estimate.cond;
    regular[std::to_string(p)] = regularCond;
    for (bool merged : {false, true})
      for (double r : ratios) {
        const StabilityConditionRun run = runSliverCase(r, merged, p);
        nlohmann::json j = conditionJson(run);
        j["volume_ratio"] = r;
        j["merged"] = merged;
        j["regular_cond"] = regularCond;
        j["cond_over_regular"] = run.estimate.cond / regularCond;
        if (merged && !(run.estimate.cond <= 100 * regularCond)) {
          mergedWithin100 = false;
          mergedBeyond100.push_back({{"degree", p}, {"volume_ratio", r}});
        }
        sliver.push_back(j);
        j["case"] = "sliver";
        s.rows.push_back(j);
        sliverPlot.add("p=" + std::to_string(p) + (merged ? " merged" : " not merged"), r,
                       run.estimate.cond);
        log("sliver p=" + std::to_string(p) + (merged ? " merged" : "") + " ratio " +
            shortNumber(r) + ": cond " + shortNumber(run.estimate.cond));
      }
  }
  s.json["sliver"] = sliver;
  s.json["sliver_regular_cond"] = regular;

  // Thin neck.
  const std::vector<double> necks =
      o.quick ? std::vector<double>{1e-1, 1e-9}
              : std::vector<double>{1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9};
  nlohmann::json neck = nlohmann::json::array();
  SeriesSet neckPlot;
  double neckMin = std::numeric_limits<double>::infinity(), neckMax = 0.0;
  for (int p : {1, 2})
    for (double e : necks) {
      const StabilityConditionRun run = runThinNeckCase(e, p);
      nlohmann::json j = conditionJson(run);
      j["eps"] = e;
      neck.push_back(j);
      j["case"] = "thin_neck";
      s.rows.push_back(j);
      neckPlot.add("p=" + std::to_string(p), e, run.estimate.cond);
      neckMin = std::min(neckMin, run.estimate.cond);
      neckMax = std::max(neckMax, run.estimate.cond);
      log("thin neck p=" + std::to_string(p) + " eps " + shortNumber(e) + ": cond " +
          shortNumber(run.estimate.cond));
    }
  s.json["thin_neck"] = neck;

  // Near-incompressible.
  const std::vector<double> nus = {0.3, 0.49, 0.499, 0.4999};
  nlohmann::json incompressible = nlohmann::json::array();
  SeriesSet tipPlot;
  double worstTip = 0.0;
  for (int p : {1, 2}) {
    double tip03 = 0.0;
    for (double nu : nus) {
      const IncompressibleRun run = runIncompressibleCase(nu, p, o.quick);
      if (nu == 0.3) tip03 = run.tip;
      const LockingSetup setup = lockingSetup(p, o.quick);
      nlohmann::json j{
          {"nu", nu},
          {"degree", p},
          {"mesh", std::to_string(setup.mesh.nx) + "x" + std::to_string(setup.mesh.ny) + "x" +
                       std::to_string(setup.mesh.nz)},
          {"dofs", run.report.dofs},
          {"eta", run.report.eta},
          {"tip", run.tip},
          {"reference", run.reference},
          {"rel_error", run.relError},
          {"tip_over_nu_0_3", run.tip / tip03},
          {"within_5_percent", std::abs(run.relError) <= 0.05},
          {"t_solve", run.report.solveSeconds}};
      incompressible.push_back(j);
      j["case"] = "incompressible";
      s.rows.push_back(j);
      worstTip = std::max(worstTip, std::abs(run.relError));
      tipPlot.add("IP p=" + std::to_string(p) + " (" + j["mesh"].get<std::string>() + ")", 0.5 - nu,
                  run.tip);
      tipPlot.add("reference (Timoshenko)", 0.5 - nu, run.reference);
      log("incompressible p=" + std::to_string(p) + " nu " + shortNumber(nu) + ": tip " +
          shortNumber(run.tip) + " (reference " + shortNumber(run.reference) + ")");
    }
  }
  s.json["incompressible"] = incompressible;

  // Scale and position.
  nlohmann::json scale = nlohmann::json::array();
  SeriesSet scalePlot;
  double worstChange = 0.0, worstChangeOverBound = 0.0;
  const std::vector<Vec3> offsets{Vec3::Zero(), Vec3(1e6, -1e6, 1e6)};
  for (ScaleProblem problem : {ScaleProblem::B1, ScaleProblem::B3}) {
    const std::string name = problem == ScaleProblem::B1 ? "B1" : "B3";
    const double base = runScaleCase(problem, 1.0, Vec3::Zero(), 2, o.quick).value;
    const double cond = scaleProblemCondition(problem, 2, o.quick);
    for (const Vec3& offset : offsets)
      for (double sc : {1e-6, 1.0, 1e6}) {
        const ScaleRun run = runScaleCase(problem, sc, offset, 2, o.quick);
        const double change = std::abs(run.value / base - 1.0);
        const double relError = problem == ScaleProblem::B1 ? run.value : run.value / base - 1.0;
        nlohmann::json j{{"problem", name},
                         {"degree", run.degree},
                         {"scale", sc},
                         {"offset", {offset.x(), offset.y(), offset.z()}},
                         {"rel_error", relError},
                         {"value", run.value},
                         {"change", change},
                         {"coordinate_resolution", run.coordinateResolution},
                         {"cond", cond},
                         {"roundoff_bound", cond * std::max(run.coordinateResolution, eps)}};
        scale.push_back(j);
        j["case"] = "scale";
        s.rows.push_back(j);
        worstChange = std::max(worstChange, change);
        worstChangeOverBound = std::max(worstChangeOverBound,
                                        change / (cond * std::max(run.coordinateResolution, eps)));
        scalePlot.add(name + (offset.isZero() ? ", offset 0" : ", offset (1e6,-1e6,1e6)"), sc,
                      std::max(change, eps));
        log("scale " + name + " x" + shortNumber(sc) + " offset " + shortNumber(offset.x()) +
            ": rel_error " + shortNumber(relError) + ", change " + shortNumber(change));
      }
  }
  s.json["scale"] = scale;

  s.json["summary"] = {{"merged_sliver_within_100x_of_regular", mergedWithin100},
                       {"merged_sliver_beyond_100x", mergedBeyond100},
                       {"thin_neck_cond_min", neckMin},
                       {"thin_neck_cond_max", neckMax},
                       {"incompressible_worst_rel_error", worstTip},
                       {"incompressible_within_5_percent", worstTip <= 0.05},
                       {"scale_worst_change", worstChange},
                       {"scale_worst_change_over_roundoff_bound", worstChangeOverBound}};

  s.plots.push_back({"stability_sliver.svg",
                     {"B4 sliver: stiffness condition estimate (IP, clamped)",
                      {"sliver volume / neighbour volume", AxisScale::Log},
                      {"condition estimate (Lanczos)", AxisScale::Log},
                      sliverPlot.series()}});
  s.plots.push_back({"stability_thin_neck.svg",
                     {"B4 thin neck: one non-convex element, clamped on x = 0",
                      {"neck height eps", AxisScale::Log},
                      {"condition estimate (Lanczos)", AxisScale::Log},
                      neckPlot.series()}});
  s.plots.push_back({"stability_incompressible.svg",
                     {"B4 near-incompressible cantilever (B3): tip deflection",
                      {"1/2 - nu", AxisScale::Log},
                      {"tip deflection", AxisScale::Linear},
                      tipPlot.series()}});
  s.plots.push_back({"stability_scale.svg",
                     {"B4 scale and position: change against the unscaled run",
                      {"scale", AxisScale::Log},
                      {"relative change (exact 0 drawn at 2.2e-16)", AxisScale::Log},
                      scalePlot.series()}});
  return s;
}

// --- meshing -------------------------------------------------------------------------------

SuiteOutput meshingSuite(const BenchOptions& o, bool quiet) {
  SuiteOutput s{"meshing", nlohmann::json::array(), nlohmann::json::array(), {}};
  const std::string torusPath = (fs::path(o.dataDir) / "torus.obj").string();
  if (!fs::exists(torusPath))
    throw InputError(torusPath + " not found; pass the folder of the bundled models with --data");
  std::vector<std::pair<std::string, TriangleSurface>> models;
  models.emplace_back("torus.obj", readSurface(torusPath));
  if (!o.quick) {
    models.emplace_back("sphere", benchmarkModel("sphere"));
    models.emplace_back("torus_knot", benchmarkModel("torus_knot"));
  }
  const std::vector<int> cells =
      o.quick ? std::vector<int>{8, 16} : std::vector<int>{16, 32, 64, 128};
  SeriesSet time, elements, volume;
  for (const auto& [name, surface] : models)
    for (int n : cells) {
      const MeshingCostRun run = runMeshingCostCase(name, surface, n);
      const MeshingBenchmarkRun& m = run.meshing;
      nlohmann::json phases = nlohmann::json::object();
      double slice = 0.0;
      for (const auto& [phase, seconds] : m.phases) {
        phases[phase] = seconds;
        if (phase == "slice") slice = seconds;
      }
      nlohmann::json j{{"model", m.model},
                       {"triangles", m.triangles},
                       {"cells", m.cells},
                       {"elements", m.elements},
                       {"hexahedra", m.hexahedra},
                       {"polyhedra", m.polyhedra},
                       {"slivers_merged", m.slivers_merged},
                       {"volume_rel_error", m.volumeRelError},
                       {"valid", m.valid},
                       {"t_total", m.secondsTotal},
                       {"t_slice", slice},
                       {"t_validate", run.geometricValidationSeconds},
                       {"t_dg_checks", run.dgCheckSeconds},
                       {"dg_elements", run.dgElements},
                       {"dg_passed", run.dgPassed},
                       {"timings_s", phases}};
      s.json.push_back(j);
      s.rows.push_back(j);
      const std::string label = m.model + " (" + std::to_string(m.triangles) + " triangles)";
      time.add(m.model + ": meshing (total)", n, m.secondsTotal);
      time.add(m.model + ": slicing", n, slice);
      time.add(m.model + ": geometric + DG validation", n,
               run.geometricValidationSeconds + run.dgCheckSeconds);
      elements.add(label, n, static_cast<double>(m.elements));
      volume.add(label, n, std::max(m.volumeRelError, std::numeric_limits<double>::epsilon()));
      if (!quiet)
        std::cout << m.model << ", " << n << " cells: " << m.elements << " elements, meshing "
                  << m.secondsTotal << " s (slice " << slice << " s), validation "
                  << run.geometricValidationSeconds << " s + DG checks " << run.dgCheckSeconds
                  << " s" << std::endl;
    }
  s.plots.push_back({"meshing_time.svg",
                     {"Meshing: wall time against grid resolution (2 cores)",
                      {"cells along the longest side", AxisScale::Log},
                      {"wall time [s]", AxisScale::Log},
                      time.series()}});
  s.plots.push_back({"meshing_elements.svg",
                     {"Meshing: elements against grid resolution",
                      {"cells along the longest side", AxisScale::Log},
                      {"elements", AxisScale::Log},
                      elements.series()}});
  s.plots.push_back({"meshing_volume_error.svg",
                     {"Meshing: relative volume error of the mesh",
                      {"cells along the longest side", AxisScale::Log},
                      {"|volume - surface volume| / volume (0 drawn at 2.2e-16)", AxisScale::Log},
                      volume.series()}});
  return s;
}

// --- cutting -------------------------------------------------------------------------------

/// One cut of the cutting suite.
struct CutRow {
  Vec3 normal;
  double offset;
  std::string name;
};

/// Corner cuts of growing depth on a unit box (normal (+-1, +-1, +-1), each corner once, so the
/// cuts never overlap and the mesh keeps its size), then one through the middle.
std::vector<CutRow> cuttingRows(bool quick) {
  const std::vector<double> depths =
      quick ? std::vector<double>{0.05, 0.3}
            : std::vector<double>{0.01, 0.04, 0.1, 0.2, 0.35, 0.5, 0.7, 0.9};
  std::vector<CutRow> rows;
  for (std::size_t k = 0; k < depths.size(); ++k) {
    const Vec3 s(k & 1 ? -1 : 1, k & 2 ? -1 : 1, k & 4 ? -1 : 1);
    const Vec3 corner(k & 1 ? 1 : 0, k & 2 ? 1 : 0, k & 4 ? 1 : 0);
    rows.push_back({s, s.dot(corner) + depths[k], "corner " + shortNumber(depths[k])});
  }
  const Vec3 n(1, 0.3, 0.1);
  rows.push_back({n, n.dot(Vec3(0.5, 0.5, 0.5)), "middle"});
  return rows;
}

/// Time per cut against the elements it splits on a ~100k-element grid, with validation
/// `none` (the cut alone) and `local` (plus the checks of the touched region; only up to
/// kLocalLimit split elements, whose region DG checks grow faster than the cut), beside a full
/// rebuild of the moment cache (what a non-incremental tool would redo after every cut).
SuiteOutput cuttingSuite(const BenchOptions& o, bool quiet) {
  constexpr std::size_t kLocalLimit = 500;
  const int n = o.quick ? 15 : 47;
  SuiteOutput s{"cutting", nlohmann::json::object(), nlohmann::json::array(), {}};
  SeriesSet time;
  nlohmann::json runs = nlohmann::json::array();
  for (ValidationLevel level : {ValidationLevel::None, ValidationLevel::Local}) {
    const std::string levelName = level == ValidationLevel::None ? "none" : "local";
    MeshEditor editor(hexGridMesh(n, n, n, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1))));
    const std::size_t elements0 = editor.mesh().numElements();
    CutOptions options;
    options.validation = level;
    for (const CutRow& row : cuttingRows(o.quick)) {
      if (level == ValidationLevel::Local && row.name == "middle") continue;
      const OperationReport r = editor.cut(Blade::plane(row.normal, row.offset), options);
      if (!r.validation.passed)
        throw std::runtime_error("cutting suite: " + row.name + ": " + r.validation.failure);
      const auto t0 = Clock::now();
      MomentCache fresh(editor.mesh(), editor.moments().degree());
      fresh.update();
      const double rebuild = secondsSince(t0);
      nlohmann::json j{{"grid", n},
                       {"elements_before", elements0},
                       {"cut", row.name},
                       {"validation", levelName},
                       {"elements_split", r.elementsSplit},
                       {"pieces_created", r.piecesCreated},
                       {"elements", editor.mesh().numElements()},
                       {"faces_reintegrated", r.facesReintegrated},
                       {"faces_total", r.facesTotal},
                       {"t_cut", r.seconds},
                       {"t_full_rebuild", rebuild},
                       {"validation_passed", r.validation.passed}};
      runs.push_back(j);
      s.rows.push_back(j);
      const double split = static_cast<double>(std::max<std::size_t>(r.elementsSplit, 1));
      time.add("cut, validation " + levelName, split, r.seconds);
      if (level == ValidationLevel::None) time.add("full moment rebuild (2 cores)", split, rebuild);
      if (!quiet)
        std::cout << "cut " << row.name << " (validation " << levelName << "): " << r.elementsSplit
                  << " split, " << r.facesReintegrated << " of " << r.facesTotal
                  << " faces integrated, " << r.seconds << " s; full rebuild " << rebuild << " s"
                  << std::endl;
      if (level == ValidationLevel::Local && r.elementsSplit > kLocalLimit) break;
    }
  }
  s.json = {{"mesh", std::to_string(n) + "^3 hexahedra in the unit box"},
            {"note",
             "each row cuts a corner off the same mesh; t_cut includes sliver merging "
             "and the validation named; t_full_rebuild integrates every face"},
            {"runs", runs}};
  s.plots.push_back(
      {"cutting.svg",
       {"Plane cuts on " + std::to_string(n * n * n) + " hexahedra: time against elements split",
        {"elements split by the cut", AxisScale::Log},
        {"wall time [s]", AxisScale::Log},
        time.series()}});
  return s;
}

void runBench(const BenchOptions& o, const CommonOptions& common) {
  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec) throw InputError("cannot create " + o.out + ": " + ec.message());
  const bool all = o.suite == "all";
  const auto t0 = Clock::now();
  auto timed = [&](const std::string& name, auto&& run) {
    const auto ts = Clock::now();
    writeSuite(o.out, run(), common.quiet);
    if (!common.quiet)
      std::cout << "suite " << name << ": " << secondsSince(ts) << " s" << std::endl;
  };
  if (all || o.suite == "accuracy")
    timed("accuracy", [&] { return accuracySuite(o, common.quiet); });
  if (all || o.suite == "table41") timed("table41", [&] { return table41Suite(common.quiet); });
  if (all || o.suite == "stability")
    timed("stability", [&] { return stabilitySuite(o, common.quiet); });
  if (all || o.suite == "meshing") timed("meshing", [&] { return meshingSuite(o, common.quiet); });
  if (all || o.suite == "cutting") timed("cutting", [&] { return cuttingSuite(o, common.quiet); });
  if (!common.quiet && all) std::cout << "all suites: " << secondsSince(t0) << " s" << std::endl;
}

}  // namespace

void addBenchCommand(CLI::App& app, const CommonOptions& common, int& exitCode) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "Benchmark suites as JSON, CSV and SVG plots: accuracy (B1), table41 (B2), "
      "stability (B4), meshing, cutting, or all");
  cmd->add_option("--suite", o->suite, "accuracy, table41, stability, meshing, cutting or all")
      ->required()
      ->check(CLI::IsMember({"accuracy", "table41", "stability", "meshing", "cutting", "all"}));
  cmd->add_option("--out", o->out, "folder for NAME.json, NAME.csv and NAME*.svg")->required();
  cmd->add_flag("--skip-sliced", o->skipSliced, "accuracy: hex grids only");
  cmd->add_flag("--quick", o->quick,
                "reduced sizes (a smoke test of every output; the figures are not the "
                "benchmark's)");
  cmd->add_option("--data", o->dataDir, "folder of the bundled models (testdata/torus.obj)")
      ->check(CLI::ExistingDirectory)
      ->capture_default_str();
  cmd->callback([o, &common, &exitCode] {
    runBench(*o, common);
    exitCode = 0;
  });
}

}  // namespace polydg::cli
