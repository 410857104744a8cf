// The polydg binary as users run it: exit codes, one-line errors, reports, nothing left behind
// on failure, enclosed volumes against VTK's, and `check` on files written by VTK itself.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/support/packages.h"
#include "tests/support/run_polydg.h"
#include "tests/support/written_figures.h"

namespace {

namespace fs = std::filesystem;

/// Relative agreement of our enclosed volume with VTK's vtkMassProperties.
constexpr double kVolumeAgreement = 1e-9;

using Result = polydg::testing::CommandResult;

Result run(const std::string& arguments) { return polydg::testing::runPolydg(arguments); }

std::string data(const std::string& name) { return polydg::testing::testData(name); }

class Cli : public polydg::testing::CommandTest {
 protected:
  std::size_t filesInDir() const {
    return static_cast<std::size_t>(
        std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  }
};

/// One line of output, mentioning `what`.
void expectOneLineError(const Result& r, const std::string& what) {
  EXPECT_EQ(r.exitCode, 2) << r.out;
  EXPECT_NE(r.out.find(what), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
}

TEST_F(Cli, InfoReportsClosedSurfaceAndVolume) {
  const Result r = run("info " + data("Lprism.ply") + " --report " + path("info.json"));
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const auto j = readJson("info.json");
  EXPECT_EQ(j["closed"], true);
  EXPECT_EQ(j["triangles"], 20);
  EXPECT_DOUBLE_EQ(j["volume"].get<double>(), 4.5);
  EXPECT_EQ(j["components"], 1);
}

TEST_F(Cli, InfoVolumesAgreeWithVtk) {
  ASSERT_TRUE(polydg::packages::pythonModule("vtkmodules.vtkFiltersCore", "python3-vtk9"));
  ASSERT_TRUE(polydg::packages::pythonModule("meshio", "python3-meshio"));
  ASSERT_TRUE(polydg::packages::assimpTestModels());
  const std::string script = std::string(POLYDG_SOURCE_DIR) + "/tests/mesh/surface_volume.py";
  for (const std::string& model :
       {data("torus.obj"), data("octahedron.stl"), data("Lprism.ply"), data("two_cubes.obj"),
        (polydg::corpus::kAssimpModels / "PLY" / "cube_binary.ply").string()}) {
    SCOPED_TRACE(model);
    const Result r = run("info " + model + " --quiet --report " + path("v.json"));
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const double ours = readJson("v.json")["volume"].get<double>();
    FILE* pipe = popen(("/usr/bin/python3 " + script + " " + model).c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::array<char, 256> line{};
    ASSERT_NE(std::fgets(line.data(), line.size(), pipe), nullptr);
    ASSERT_EQ(pclose(pipe), 0);
    const double vtk = std::stod(line.data());
    EXPECT_NEAR(std::abs(ours), vtk, kVolumeAgreement * vtk);
  }
}

TEST_F(Cli, BadInputGetsOneLineErrorAndNoOutput) {
  expectOneLineError(run("info " + path("missing.obj")), "missing.obj");
  std::ofstream(path("empty.obj")) << "";
  expectOneLineError(run("info " + path("empty.obj")), "empty.obj");
  std::ofstream(path("points.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n";
  const Result points = run("mesh " + path("points.obj") + " --cells 4 -o " + path("out.vtu"));
  expectOneLineError(points, "no triangles");
  std::ofstream(path("garbage.vtu")) << "<VTKFile type=\"PolyData\"/>";
  expectOneLineError(run("check " + path("garbage.vtu")), "garbage.vtu");
  EXPECT_EQ(filesInDir(), 3u);  // nothing written besides the three inputs
}

TEST_F(Cli, MeshRefusesOpenSurfaceWithoutRepairAndLeavesNothing) {
  // A cube with one triangle missing: open.
  std::ofstream(path("open.obj")) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\n"
                                     "v 1 1 1\nv 0 1 1\nf 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\n"
                                     "f 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\n"
                                     "f 4 1 5\n";
  const Result refused = run("mesh " + path("open.obj") + " --cells 4 -o " + path("out.vtu") +
                             " --report " + path("r.json"));
  expectOneLineError(refused, "open (3 boundary edges)");
  EXPECT_NE(refused.out.find("--repair"), std::string::npos);
  EXPECT_FALSE(fs::exists(path("out.vtu")));
  EXPECT_FALSE(fs::exists(path("r.json")));

  const Result filled = run("mesh " + path("open.obj") + " --cells 4 --repair fill -o " +
                            path("out.vtu") + " --report " + path("r.json") + " --quiet");
  ASSERT_EQ(filled.exitCode, 0) << filled.out;
  const auto j = readJson("r.json");
  EXPECT_EQ(j["input"]["closed"], false);
  EXPECT_EQ(j["input"]["repairs"].size(), 1u);
  EXPECT_NEAR(j["output"]["volume"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(j["validation"]["passed"], true);
}

TEST_F(Cli, MeshWritesAValidMeshAndReport) {
  const Result r = run("mesh " + data("torus.obj") + " --cells 12 -o " + path("t.vtu") +
                       " --report " + path("t.json") + " --quiet");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_TRUE(r.out.empty()) << r.out;  // --quiet
  const auto j = readJson("t.json");
  for (const char* key : {"input", "output", "volume_rel_error", "validation", "timings_s"})
    EXPECT_TRUE(j.contains(key)) << key;
  for (const char* key :
       {"vertices", "triangles", "closed", "self_intersecting", "volume", "repairs"})
    EXPECT_TRUE(j["input"].contains(key)) << key;
  for (const char* key : {"elements", "hexahedra", "polyhedra", "nonconvex", "faces",
                          "interior_faces", "boundary_faces", "volume", "slivers_merged"})
    EXPECT_TRUE(j["output"].contains(key)) << key;
  EXPECT_LT(j["volume_rel_error"].get<double>(), 1e-12);
  EXPECT_EQ(j["output"]["elements"].get<int>(),
            j["output"]["hexahedra"].get<int>() + j["output"]["polyhedra"].get<int>());

  const Result check = run("check " + path("t.vtu") + " --report " + path("c.json"));
  EXPECT_EQ(check.exitCode, 0) << check.out;
  const auto c = readJson("c.json");
  EXPECT_EQ(c["passed"], true);
  EXPECT_EQ(c["components"], 1);
  EXPECT_EQ(c["elements"], j["output"]["elements"]);
  EXPECT_NEAR(c["volume"].get<double>(), j["input"]["volume"].get<double>(),
              1e-12 * j["input"]["volume"].get<double>());
  // (Overwrite guards: Commands.NoCommandOverwritesItsInput, with each guard reached alone.)
}

/// Tolerance of the DG patch test in reports (physics/checks/dg_checks.h's
/// kLocalPatchTestTolerance).
constexpr double kPatchTolerance = 1e-9;

TEST_F(Cli, CheckReportsTheDgChecks) {
  ASSERT_EQ(
      run("mesh " + data("torus.obj") + " --cells 8 -o " + path("t.vtu") + " --quiet").exitCode, 0);
  const Result r = run("check " + path("t.vtu") + " --report " + path("c.json"));
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("local patch test error"), std::string::npos) << r.out;
  const auto c = readJson("c.json");
  for (const char* key : {"passed", "elements", "components", "volume", "problems", "validation"})
    EXPECT_TRUE(c.contains(key)) << key;
  EXPECT_EQ(c["passed"], true);
  const auto& v = c["validation"];
  EXPECT_EQ(v["passed"], true);
  EXPECT_EQ(v["geometry_passed"], true);
  EXPECT_EQ(v["dg_passed"], true);
  EXPECT_EQ(v["dg_degree"], 1);
  EXPECT_EQ(v["elements"], c["elements"]);
  EXPECT_EQ(v["dg_elements_checked"], c["elements"]);
  EXPECT_LT(v["patch_test_error"].get<double>(), kPatchTolerance);
  EXPECT_EQ(v["rigid_mode_failures"], 0);
  const int components = v["components"].get<int>();
  EXPECT_EQ(components, 1);
  EXPECT_EQ(v["rigid_modes"].get<int>(), 6 * components);
  EXPECT_EQ(v["rigid_modes_global"], v["rigid_modes"]);
  EXPECT_EQ(v["rigid_modes_expected"].get<int>(), 6 * components);

  const Result p2 =
      run("check " + path("t.vtu") + " --degree 2 --quiet --report " + path("c2.json"));
  ASSERT_EQ(p2.exitCode, 0) << p2.out;
  const auto c2 = readJson("c2.json")["validation"];
  EXPECT_EQ(c2["dg_degree"], 2);
  EXPECT_LT(c2["patch_test_error"].get<double>(), kPatchTolerance);
  EXPECT_EQ(c2["rigid_modes"].get<int>(), 6 * components);

  const Result skipped =
      run("check " + path("t.vtu") + " --no-dg --quiet --report " + path("c3.json"));
  ASSERT_EQ(skipped.exitCode, 0) << skipped.out;
  const auto c3 = readJson("c3.json")["validation"];
  EXPECT_EQ(c3["passed"], true);
  EXPECT_EQ(c3["dg_checked"], false);
  EXPECT_TRUE(c3["patch_test_error"].is_null());
  EXPECT_TRUE(c3["rigid_modes"].is_null());
  EXPECT_EQ(run("check " + path("t.vtu") + " --degree 4").exitCode, 2);
}

TEST_F(Cli, CheckFailsTheDgChecksOnANonPlanarFace) {
  // Two unit cubes sharing the face x = 1, whose corner (1, 0, 1) is moved to x = 1.001: only
  // the shared face is non-planar. With a loose planarity tolerance the geometry passes and the
  // DG patch test fails; with the default one the geometry fails and the DG checks are skipped.
  std::string points;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i)
        points += (i == 1 && j == 0 && k == 1 ? std::string("1.001") : std::to_string(i)) + " " +
                  std::to_string(j) + " " + std::to_string(k) + " ";
  std::ofstream(path("bent.vtu"))
      << "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
         "byte_order=\"LittleEndian\">\n<UnstructuredGrid><Piece NumberOfPoints=\"12\" "
         "NumberOfCells=\"2\">\n<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" "
         "format=\"ascii\">"
      << points
      << "</DataArray></Points>\n<Cells><DataArray type=\"Int32\" Name=\"connectivity\" "
         "format=\"ascii\">0 1 4 3 6 7 10 9 1 2 5 4 7 8 11 10</DataArray>\n<DataArray "
         "type=\"Int32\" Name=\"offsets\" format=\"ascii\">8 16</DataArray>\n<DataArray "
         "type=\"UInt8\" Name=\"types\" format=\"ascii\">12 12</DataArray>\n</Cells></Piece>"
         "</UnstructuredGrid></VTKFile>\n";
  const Result loose =
      run("check " + path("bent.vtu") + " --planarity-tolerance 0.01 --report " + path("c.json"));
  EXPECT_EQ(loose.exitCode, 1) << loose.out;
  EXPECT_NE(loose.out.find("INVALID"), std::string::npos) << loose.out;
  EXPECT_NE(loose.out.find("local patch test"), std::string::npos) << loose.out;
  const auto c = readJson("c.json");
  EXPECT_EQ(c["passed"], false);
  const auto& v = c["validation"];
  EXPECT_EQ(v["passed"], false);
  EXPECT_EQ(v["geometry_passed"], true);
  EXPECT_EQ(v["dg_passed"], false);
  EXPECT_GT(v["patch_test_error"].get<double>(), 1e3 * kPatchTolerance);
  EXPECT_EQ(v["patch_test_failures"], 2);
  EXPECT_FALSE(v["messages"].empty());

  const Result strict = run("check " + path("bent.vtu") + " --quiet --report " + path("c.json"));
  EXPECT_EQ(strict.exitCode, 1) << strict.out;
  const auto s = readJson("c.json")["validation"];
  EXPECT_EQ(s["geometry_passed"], false);
  EXPECT_EQ(s["dg_checked"], false);
  EXPECT_TRUE(s["patch_test_error"].is_null());
  EXPECT_TRUE(s.contains("dg_note"));
}

TEST_F(Cli, MeshReportsTheDgChecks) {
  const Result r = run("mesh " + data("torus.obj") + " --cells 8 -o " + path("t.vtu") +
                       " --report " + path("t.json"));
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("DG checks (degree 1,"), std::string::npos) << r.out;
  const auto j = readJson("t.json");
  const auto& v = j["validation"];
  EXPECT_EQ(v["passed"], true);
  EXPECT_EQ(v["geometry_passed"], true);
  EXPECT_EQ(v["dg_passed"], true);
  EXPECT_LT(v["patch_test_error"].get<double>(), kPatchTolerance);
  EXPECT_EQ(v["rigid_mode_failures"], 0);
  // Every element but the congruent grid cells, of which one is checked for all.
  const int hexahedra = j["output"]["hexahedra"].get<int>();
  EXPECT_EQ(v["dg_elements_checked"].get<int>(),
            j["output"]["elements"].get<int>() - hexahedra + (hexahedra > 0 ? 1 : 0));
  EXPECT_GE(v["dg_seconds"].get<double>(), 0.0);
  EXPECT_EQ(j["timings_s"]["dg_checks"], v["dg_seconds"]);

  const Result skipped = run("mesh " + data("torus.obj") + " --cells 8 --no-dg --quiet -o " +
                             path("t.vtu") + " --report " + path("t.json"));
  ASSERT_EQ(skipped.exitCode, 0) << skipped.out;
  const auto s = readJson("t.json");
  EXPECT_EQ(s["validation"]["dg_checked"], false);
  EXPECT_TRUE(s["validation"]["patch_test_error"].is_null());
  EXPECT_TRUE(s["timings_s"]["dg_checks"].is_null());
}

TEST_F(Cli, CheckAcceptsVtkWrittenFilesAndRejectsBrokenOnes) {
  const char* dir = std::getenv("POLYDG_VTK_FILES_DIR");
  if (!dir) GTEST_SKIP() << "run through ctest's cli_check_vtk_files (needs VTK-written files)";
  const std::string base = std::string(dir) + "/vtk_cells";
  for (const char* variant : {"", "_ascii", "_binary", "_raw", "_uncompressed", "_linear"}) {
    const Result r = run("check " + base + variant + ".vtu --report " + path("c.json"));
    EXPECT_EQ(r.exitCode, 0) << variant << ": " << r.out;
    EXPECT_EQ(readJson("c.json")["passed"], true) << variant;
  }
  const Result inverted = run("check " + base + "_inverted.vtu --report " + path("c.json"));
  EXPECT_EQ(inverted.exitCode, 1) << inverted.out;
  EXPECT_GT(readJson("c.json")["problems"]["non_positive_elements"].get<int>(), 0);
  const Result leaky = run("check " + base + "_leaky.vtu --report " + path("c.json"));
  EXPECT_EQ(leaky.exitCode, 1) << leaky.out;
  EXPECT_GT(readJson("c.json")["problems"]["open_elements"].get<int>(), 0);
}

std::string fileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST_F(Cli, SimulateRunsTheExampleSceneAndWritesATimeSeries) {
  ASSERT_EQ(run("mesh " + data("beam.obj") + " --cells 20 --quiet -o " + path("beam.vtu")).exitCode,
            0);
  const std::string before = fileText(path("beam.vtu"));
  const std::string scene = std::string(POLYDG_SOURCE_DIR) + "/examples/scenes/beam_cut.json";
  const Result r = run("simulate " + path("beam.vtu") + " --scene " + scene + " -o " + path("out") +
                       " --report " + path("r.json"));
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_NE(r.out.find("wrote"), std::string::npos) << r.out;
  EXPECT_EQ(fileText(path("beam.vtu")), before);  // the input is never touched
  const auto j = readJson("r.json");
  EXPECT_EQ(j["command"], "simulate");
  EXPECT_EQ(j["steps"].size(), 60u);
  EXPECT_EQ(j["cuts"].size(), 1u);
  EXPECT_EQ(j["cuts"][0]["operation"]["validation"]["passed"], true);
  // The cut at x = 5.1 splits the 4 elements of its column into 8 pieces and removes nothing;
  // every piece takes its parent's fields exactly.
  const auto& cut = j["cuts"][0];
  EXPECT_EQ(cut["operation"]["elements_split"], 4);
  EXPECT_EQ(cut["operation"]["pieces_created"], 8);
  EXPECT_EQ(cut["elements_after"].get<int>(), cut["elements_before"].get<int>() + 8 - 4);
  EXPECT_EQ(cut["exact"], cut["elements_after"]);
  EXPECT_EQ(cut["operation"]["volume_removed"].get<double>(), 0.0);
  EXPECT_LT(cut["operation"]["validation"]["volume_rel_error"].get<double>(), 1e-12);
  // Its latency: the cut, the new solver and the fields carried over (its "seconds"), then the
  // next step.
  const auto& latency = cut["cut_seconds"];
  for (const char* phase : {"cut", "check", "solver", "transfer", "next_step"})
    EXPECT_GT(latency[phase].get<double>(), 0.0) << phase;
  EXPECT_DOUBLE_EQ(latency["latency"].get<double>(),
                   cut["seconds"].get<double>() + latency["next_step"].get<double>());
  for (const char* phase : {"rotation_seconds", "assembly_seconds", "solve_seconds"})
    EXPECT_TRUE(j["steps"][0].contains(phase)) << phase;
  EXPECT_NE(r.out.find(" steps/s)"), std::string::npos) << r.out;
  // The physics of the run, step by step (the beam: mass 10, gravity (0, 0, -1)): the gravity
  // term -F_g.U is m g dz of the centre of mass, and backward Euler without damping or loads
  // only dissipates: kinetic + elastic + gravity never grows (measured: it falls by at least
  // 1.6e-3 per step, also across the cut, where the DG form loses the cut faces' terms).
  const double mass = 10.0, z0 = j["initial"]["centre_of_mass"][2].get<double>();
  double previous = 0.0;
  for (const auto& step : j["steps"]) {
    const double z = step["centre_of_mass"][2].get<double>();
    EXPECT_NEAR(step["gravity"].get<double>(), mass * (z - z0), 1e-12 * mass) << step["t"];
    const double total = step["kinetic"].get<double>() + step["elastic"].get<double>() +
                         step["gravity"].get<double>();
    EXPECT_LT(total, previous) << step["t"];
    previous = total;
  }
  for (const auto& frame : j["frames"])
    EXPECT_TRUE(fs::exists(dir_ / "out" / frame["file"].get<std::string>())) << frame;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "scene.pvd"));
  for (const char* phase : {"rotation", "assembly", "solve", "cut", "output", "setup"})
    EXPECT_TRUE(j["timings_s"].contains(phase)) << phase;

  const Result quiet =
      run("-q simulate " + path("beam.vtu") + " --scene " + scene + " -o " + path("out2"));
  EXPECT_EQ(quiet.exitCode, 0) << quiet.out;
  EXPECT_EQ(quiet.out, "");
}

TEST_F(Cli, SolveAndSimulateWriteTheDeformedEmbeddedSurface) {
  ASSERT_EQ(run("mesh " + data("ball.obj") + " --cells 6 --quiet -o " + path("ball.vtu")).exitCode,
            0);
  // solve --surface: the surface the mesh was sliced from, deformed.
  const Result solved = run("solve " + path("ball.vtu") + " -o " + path("s.vtu") +
                            " --degree 1 --E 1e6 --density 1000 --gravity 100,0,0 "
                            "--clamp-below 0,0,1,0.7 --surface " +
                            path("s.vtp") + " --report " + path("s.json"));
  ASSERT_EQ(solved.exitCode, 0) << solved.out;
  EXPECT_NE(solved.out.find("wrote " + path("s.vtp")), std::string::npos) << solved.out;
  const auto s = readJson("s.json");
  EXPECT_EQ(s["embedded_surface"]["surface"], data("ball.obj"));
  EXPECT_EQ(s["embedded_surface"]["points"], 642);
  // The files, read back by VTK: the solve does the work its energy says (Clapeyron: energy =
  // 1/2 rho g . integral of u, to 1e-15 measured), and the surface, which rides on it, moves as
  // far as the mesh does at its top (the ball's pole, in both): the MLS fit against the
  // vertex means, 0.21% apart measured.
  const auto mesh = polydg::testing::writtenFigures(path("s.vtu"));
  const auto surface = polydg::testing::writtenFigures(path("s.vtp"));
  ASSERT_FALSE(mesh.is_null() || surface.is_null());
  const double energy = s["energy"].get<double>();
  EXPECT_NEAR(polydg::testing::gravityWorkHalf(mesh, 1000.0, {100.0, 0.0, 0.0}), energy,
              1e-12 * energy);
  EXPECT_EQ(surface["points"], 642);
  const double moved = s["embedded_surface"]["max_displacement"].get<double>();
  EXPECT_NEAR(surface["max_point_displacement"].get<double>(), moved, 1e-15 * moved);
  const double meshMoved = mesh["max_point_displacement"].get<double>();
  EXPECT_NEAR(moved, meshMoved, 0.005 * meshMoved);
  EXPECT_NE(fileText(path("s.vtp")).find("<VTKFile type=\"PolyData\""), std::string::npos);
  expectOneLineError(run("solve " + path("ball.vtu") + " -o " + path("t.vtu") +
                         " --clamp-below 0,0,1,0.7 --surface " + path("t.ply")),
                     "the deformed surface is written as a .vtp file");

  // simulate: the bundled drop scene, shortened; each frame lists the surface as part 1.
  nlohmann::json scene;
  std::ifstream(std::string(POLYDG_SOURCE_DIR) + "/examples/scenes/ball_drop.json") >> scene;
  scene.erase("duration");
  scene["steps"] = 100;
  std::ofstream(path("drop.json")) << scene.dump();
  const Result r = run("-q simulate " + path("ball.vtu") + " --scene " + path("drop.json") +
                       " -o " + path("drop") + " --report " + path("r.json"));
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const auto j = readJson("r.json");
  EXPECT_EQ(j["embedding"]["points"], 642);
  EXPECT_EQ(j["contact"]["points"], "surface");
  bool touched = false;
  for (const auto& step : j["steps"]) touched = touched || step["contacts"].get<int>() > 0;
  EXPECT_TRUE(touched);  // it reaches the ground at t = 0.33 (with its mass damping)
  const std::string pvd = fileText((dir_ / "drop" / "scene.pvd").string());
  for (const auto& frame : j["frames"]) {
    const std::string vtp = frame["surface"].get<std::string>();
    EXPECT_TRUE(fs::exists(dir_ / "drop" / vtp)) << vtp;
    EXPECT_NE(pvd.find("part=\"1\" file=\"" + vtp + "\""), std::string::npos) << vtp;
  }
}

TEST_F(Cli, SimulateRefusesABadSceneBeforeRunning) {
  ASSERT_EQ(run("mesh " + data("beam.obj") + " --cells 10 --quiet -o " + path("beam.vtu")).exitCode,
            0);
  std::ofstream(path("bad.json"))
      << R"({"material": {"E": 1000, "nu": 0.3, "density": 1}, "dt": 0.1, "steps": 5,
            "fixed": [{"plane": [1, 0, 0, 0]}], "cuts": [{"time": 0.2, "plnae": [1, 0, 0, 5]}]})";
  const Result r =
      run("simulate " + path("beam.vtu") + " --scene " + path("bad.json") + " -o " + path("out"));
  expectOneLineError(r, "cuts[0]: a cut needs exactly one of");
  EXPECT_FALSE(fs::exists(dir_ / "out"));  // nothing ran

  std::ofstream(path("away.json"))
      << R"({"material": {"E": 1000, "nu": 0.3, "density": 1}, "dt": 0.1, "steps": 5,
            "fixed": [{"below": [1, 0, 0, -1]}]})";
  expectOneLineError(
      run("simulate " + path("beam.vtu") + " --scene " + path("away.json") + " -o " + path("out")),
      "selects no boundary face");
  expectOneLineError(
      run("simulate " + data("beam.obj") + " --scene " + path("away.json") + " -o " + path("out")),
      "simulate reads simulation meshes (.vtu)");
}

}  // namespace
