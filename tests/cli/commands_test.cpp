// The contract of every polydg command with its user: no command overwrites its input (each
// guard tested on its own, behind every other check), hostile option values are refused with one
// line naming the option, unknown commands are named, boundary regions (plane, below, box) hold
// real models, the sliver threshold travels with the mesh, `--solver auto` picks by size, and an
// operation that leaves nothing writes nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/support/run_polydg.h"
#include "tests/support/written_figures.h"

namespace {

namespace fs = std::filesystem;
using polydg::testing::CommandResult;
using polydg::testing::runPolydg;
using polydg::testing::testData;

class Commands : public polydg::testing::CommandTest {
 protected:
  /// The bytes of a file, to show it was not touched.
  static std::string bytes(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  /// A torus meshed at `cells` into DIR/name.
  std::string meshTorus(const std::string& name, int cells = 6) {
    const CommandResult r = runPolydg("mesh " + testData("torus.obj") + " --cells " +
                                      std::to_string(cells) + " -o " + path(name) + " --quiet");
    EXPECT_EQ(r.exitCode, 0) << r.out;
    return path(name);
  }
};

/// Exit 2 with one line naming `what`.
void expectRefused(const CommandResult& r, const std::string& what) {
  EXPECT_EQ(r.exitCode, 2) << r.out;
  EXPECT_NE(r.out.find(what), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
}

// Each guard is reached with everything else valid (a .vtu output for a .vtu input, a report
// path that is the input), so removing any one guard makes its case overwrite the input.
TEST_F(Commands, NoCommandOverwritesItsInput) {
  const std::string mesh = meshTorus("m.vtu");
  const std::string original = bytes(mesh);
  const std::string refused = "refusing to overwrite the input";
  expectRefused(runPolydg("solve " + mesh + " -o " + mesh + " --clamp-below 0,0,1,0"), refused);
  expectRefused(runPolydg("cut " + mesh + " -o " + mesh + " --plane 1,0,0,0.1"), refused);
  expectRefused(runPolydg("check " + mesh + " --report " + mesh), refused);
  expectRefused(runPolydg("info " + mesh + " --report " + mesh), refused);
  expectRefused(runPolydg("solve " + mesh + " -o " + path("s.vtu") + " --clamp-below 0,0,1,0 " +
                          "--report " + mesh),
                refused);
  expectRefused(runPolydg("cut " + mesh + " -o " + path("c.vtu") + " --plane 1,0,0,0.1 " +
                          "--report " + mesh),
                refused);
  // The same file under another name (a symbolic link) is still the input.
  fs::create_symlink(mesh, path("link.vtu"));
  expectRefused(runPolydg("cut " + mesh + " -o " + path("link.vtu") + " --plane 1,0,0,0.1"),
                refused);
  EXPECT_EQ(bytes(mesh), original);

  // polydg mesh reads a surface: one named .vtu is refused as output and as report.
  const std::string surface = path("surface.vtu");
  fs::copy_file(testData("torus.obj"), surface);
  expectRefused(runPolydg("mesh " + surface + " --cells 4 -o " + surface), refused);
  expectRefused(
      runPolydg("mesh " + surface + " --cells 4 -o " + path("x.vtu") + " --report " + surface),
      refused);
  EXPECT_EQ(bytes(surface), bytes(testData("torus.obj")));

  // polydg run: its report may not replace the pipeline file.
  const std::string pipeline = path("p.json");
  std::ofstream(pipeline) << R"({"steps": [{"step": "mesh", "cells": 4}]})";
  const std::string text = bytes(pipeline);
  expectRefused(runPolydg("run " + pipeline + " --inputs " + testData("torus.obj") + " --out " +
                          path("runs") + " --report " + pipeline),
                refused);
  EXPECT_EQ(bytes(pipeline), text);
}

// A file output into a folder that does not exist is refused before the work whose result it
// would hold: no mesh written and then the report refused, no case exported, no frames written.
TEST_F(Commands, OutputsIntoAMissingFolderAreRefusedBeforeTheWork) {
  const std::string mesh = meshTorus("m.vtu");
  const std::string missing = path("missing") + "/";
  const std::string refused = "the folder " + path("missing") + " does not exist";
  const std::string torus = testData("torus.obj");
  expectRefused(runPolydg("mesh " + torus + " --cells 4 -o " + missing + "x.vtu"), refused);
  expectRefused(runPolydg("mesh " + torus + " --cells 4 -o " + path("x.vtu") + " --report " +
                          missing + "r.json"),
                refused);
  EXPECT_FALSE(fs::exists(path("x.vtu")));
  const std::string cut = "cut " + mesh + " --plane 1,0,0,0.1 -o ";
  expectRefused(runPolydg(cut + missing + "c.vtu"), refused);
  expectRefused(runPolydg(cut + path("c.vtu") + " --report " + missing + "r.json"), refused);
  EXPECT_FALSE(fs::exists(path("c.vtu")));
  const std::string solve = "solve " + mesh + " --clamp-below 0,0,1,0 -o ";
  expectRefused(runPolydg(solve + missing + "s.vtu"), refused);
  expectRefused(runPolydg(solve + path("s.vtu") + " --report " + missing + "r.json"), refused);
  EXPECT_FALSE(fs::exists(path("s.vtu")));
  expectRefused(runPolydg("check " + mesh + " --report " + missing + "r.json"), refused);
  expectRefused(runPolydg("info " + mesh + " --report " + missing + "r.json"), refused);
  expectRefused(runPolydg("export " + mesh + " --format openfoam -o " + path("case") +
                          " --report " + missing + "r.json"),
                refused);
  EXPECT_FALSE(fs::exists(path("case")));
  const std::string scene = path("scene.json");
  std::ofstream(scene) << R"({"material": {"E": 1000, "nu": 0.3, "density": 1}, "dt": 0.01,
                             "steps": 1})";
  expectRefused(runPolydg("simulate " + mesh + " --scene " + scene + " -o " + path("frames") +
                          " --report " + missing + "r.json"),
                refused);
  EXPECT_FALSE(fs::exists(path("frames")));
  const std::string pipeline = path("p.json");
  std::ofstream(pipeline) << R"({"steps": [{"step": "mesh", "cells": 4}]})";
  expectRefused(runPolydg("run " + pipeline + " --inputs " + torus + " --out " + path("runs") +
                          " --report " + missing + "r.json"),
                refused);
  EXPECT_FALSE(fs::exists(path("runs")));
  // A folder where the file should go.
  fs::create_directory(path("folder.vtu"));
  expectRefused(runPolydg(cut + path("folder.vtu")), "it is a folder");
  // A write that fails only when it is made (/proc takes no new files; as another user than
  // root, its folder is refused first) names the output, not the surface that was read.
  const CommandResult late = runPolydg("mesh " + torus + " --cells 4 -o /proc/polydg-x.vtu");
  expectRefused(late, "polydg: error: cannot write /proc/polydg-x.vtu");
  EXPECT_EQ(late.out.find(torus), std::string::npos) << late.out;
}

// Finite values whose loads or solution overflow (a traction near the largest double, gravity
// times a density) are refused with one line, not written as a displacement of NaN or zero.
TEST_F(Commands, LoadsThatOverflowAreRefused) {
  const std::string mesh = meshTorus("m.vtu");
  const std::string overflow = "the loads overflow double precision";
  const std::string solve = "solve " + mesh + " -o " + path("s.vtu") + " --clamp-below 0,0,1,-0.3 ";
  // A traction whose load still fits, but not the displacement it would cause.
  expectRefused(runPolydg(solve + "--traction-below 0,0,-1,-0.3:0,0,1e308"),
                "the solution overflows double precision");
  expectRefused(runPolydg(solve + "--gravity 0,0,1e308"), overflow);
  expectRefused(runPolydg(solve + "--density 1e299 --gravity 0,0,1e100"), overflow);
  EXPECT_FALSE(fs::exists(path("s.vtu")));
  const std::string scene = path("scene.json");
  std::ofstream(scene) << R"({"material": {"E": 1000, "nu": 0.3, "density": 1}, "dt": 0.01,
                             "steps": 2, "gravity": [0, 0, 1e308]})";
  expectRefused(runPolydg("simulate " + mesh + " --scene " + scene + " -o " + path("frames")),
                overflow);
  // A motion too fast for double precision stops the first step (a failed step: exit 1).
  std::ofstream(scene) << R"({"material": {"E": 1000, "nu": 0.3, "density": 1}, "dt": 0.01,
                             "steps": 2, "initial": {"velocity": [1e308, 0, 0]}})";
  const CommandResult fast =
      runPolydg("simulate " + mesh + " --scene " + scene + " -o " + path("frames2"));
  EXPECT_EQ(fast.exitCode, 1) << fast.out;
  EXPECT_NE(fast.out.find("the time step's right-hand side overflows double precision"),
            std::string::npos)
      << fast.out;
}

TEST_F(Commands, NonFiniteAndOutOfRangeValuesNameTheirOption) {
  const std::string mesh = meshTorus("m.vtu");
  const std::string solve = "solve " + mesh + " -o " + path("s.vtu") + " ";
  expectRefused(runPolydg(solve + "--clamp x=nan"), "--clamp");
  expectRefused(runPolydg(solve + "--clamp x=inf"), "--clamp");
  expectRefused(runPolydg(solve + "--clamp-below 0,0,1,nan"), "--clamp-below");
  expectRefused(runPolydg(solve + "--clamp-box 0,0,0,1,1"), "--clamp-box");
  expectRefused(runPolydg(solve + "--clamp-box 1,0,0,0,1,1"), "--clamp-box");
  expectRefused(runPolydg(solve + "--clamp-plane 0,0,0,1"), "--clamp-plane");
  expectRefused(runPolydg(solve + "--clamp x=0 --E nan"), "--E");
  expectRefused(runPolydg(solve + "--clamp x=0 --E -1"), "--E");
  expectRefused(runPolydg(solve + "--clamp x=0 --nu 0.5"), "--nu");
  expectRefused(runPolydg(solve + "--clamp x=0 --density inf"), "--density");
  expectRefused(runPolydg(solve + "--clamp x=0 --gravity 0,0,nan"), "--gravity");
  expectRefused(runPolydg(solve + "--clamp x=0 --traction x=1:0,0"), "--traction");
  expectRefused(runPolydg(solve + "--clamp x=0 --eta inf"), "--eta");
  expectRefused(runPolydg(solve + "--clamp x=0 --method sfem"), "--method");
  // The material's and the discretization's own checks, named by the option.
  expectRefused(runPolydg(solve + "--clamp x=0 --E 0"),
                "Young's modulus must be a positive number");
  expectRefused(runPolydg(solve + "--clamp x=0 --nu -1"), "Poisson's ratio must lie in (-1, 0.5)");
  // Finite but beyond what the material's terms can hold: the bound is named.
  expectRefused(runPolydg(solve + "--clamp x=0 --E 1e308"), "a positive number below 1e300");
  expectRefused(runPolydg(solve + "--clamp x=0 --density 1e300"), "a number >= 0 and below 1e300");
  expectRefused(runPolydg(solve + "--clamp x=0 --degree 4"), "--degree");
  expectRefused(runPolydg(solve + "--clamp x=0 --degree 0"), "must be 1, 2 or 3");
  expectRefused(runPolydg(solve + "--clamp x=0 --eta 0"), "the penalty must be a positive number");
  expectRefused(runPolydg("check " + mesh + " --degree 4"), "must be 1, 2 or 3");
  expectRefused(runPolydg("cut " + mesh + " -o " + path("c.vtu") + " --plane 1,0,0,nan"),
                "--plane");
  expectRefused(runPolydg("cut " + mesh + " -o " + path("c.vtu") + " --plane 1,0,0,0 " +
                          "--merge-slivers nan"),
                "--merge-slivers");
  expectRefused(runPolydg("mesh " + testData("torus.obj") + " -o " + path("t.vtu") + " --cell inf"),
                "--cell");
  expectRefused(runPolydg("mesh " + testData("torus.obj") + " -o " + path("t.vtu") +
                          " --cells 4 --merge-slivers nan"),
                "--merge-slivers");
  expectRefused(runPolydg("check " + mesh + " --planarity-tolerance nan"), "--planarity-tolerance");
  EXPECT_FALSE(fs::exists(path("s.vtu")));
  EXPECT_FALSE(fs::exists(path("c.vtu")));
  EXPECT_FALSE(fs::exists(path("t.vtu")));
}

TEST_F(Commands, UnknownCommandsAndChoicesAreNamed) {
  expectRefused(runPolydg("animate x.vtu"), "unknown command 'animate'");
  const CommandResult help = runPolydg("mesh --help");
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.out.find("none|fill|wrap"), std::string::npos) << help.out;
  EXPECT_EQ(help.out.find("->"), std::string::npos) << help.out;  // CLI11's enum mapping
  expectRefused(runPolydg("mesh " + testData("torus.obj") + " --cells 4 -o " + path("t.vtu") +
                          " --repair glue"),
                "'glue' is not one of none, fill, wrap");
}

TEST_F(Commands, OverflowingCoordinatesAndMalformedLinesAreReported) {
  std::ofstream(path("huge.obj")) << "v 0 0 0\nv 1e308 0 0\nv 0 1e308 0\nv 0 0 1e308\n"
                                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const CommandResult huge =
      runPolydg("mesh " + path("huge.obj") + " --cells 4 -o " + path("h.vtu"));
  expectRefused(huge, "too large for double precision");
  std::ofstream(path("empty_f.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                        "f 1 3 2\nf\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const CommandResult warned =
      runPolydg("mesh " + path("empty_f.obj") + " --cells 4 -o " + path("w.vtu"));
  EXPECT_EQ(warned.exitCode, 0) << warned.out;
  EXPECT_NE(warned.out.find("polydg: warning: " + path("empty_f.obj") + ":6:"), std::string::npos)
      << warned.out;
  std::ofstream(path("bad_v.obj")) << "v 0 0 0\nv 1 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\n";
  expectRefused(runPolydg("mesh " + path("bad_v.obj") + " --cells 4 -o " + path("b.vtu")),
                "bad_v.obj:2:");
}

TEST_F(Commands, ACutThatRemovesEverythingExitsOneAndWritesNothing) {
  const std::string mesh = meshTorus("m.vtu");
  const CommandResult r = runPolydg("cut " + mesh + " -o " + path("none.vtu") +
                                    " --plane 0,0,1,5 --remove-side - --report " + path("r.json"));
  EXPECT_EQ(r.exitCode, 1) << r.out;
  EXPECT_NE(r.out.find("left no element"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_FALSE(fs::exists(path("none.vtu")));
  EXPECT_EQ(readJson("r.json")["passed"], false);
}

// `polydg mesh` then `polydg cut` applies the sliver threshold of one `polydg run` of the same
// steps: the grid cell travels with the mesh in its field data.
TEST_F(Commands, MeshThenCutUsesTheThresholdOfARun) {
  const CommandResult meshed = runPolydg("mesh " + testData("torus.obj") + " --cells 10 " +
                                         "--merge-slivers 0.02 -o " + path("m.vtu") + " --quiet");
  ASSERT_EQ(meshed.exitCode, 0) << meshed.out;
  const CommandResult cut = runPolydg("cut " + path("m.vtu") + " -o " + path("c.vtu") +
                                      " --plane 0.3,1,0.2,0.1 --report " + path("cut.json"));
  ASSERT_EQ(cut.exitCode, 0) << cut.out;
  std::ofstream(path("p.json")) << R"({"steps": [
      {"step": "mesh", "cells": 10, "merge_slivers": 0.02},
      {"step": "cut", "plane": [0.3, 1, 0.2, 0.1]}]})";
  const CommandResult run =
      runPolydg("run " + path("p.json") + " --inputs " + testData("torus.obj") + " --out " +
                path("runs") + " --quiet --report " + path("run.json"));
  ASSERT_EQ(run.exitCode, 0) << run.out;
  const auto separate = readJson("cut.json")["operations"][0];
  const auto inRun = readJson("run.json")["inputs"][0]["steps"][1]["operations"][0];
  EXPECT_GT(separate["sliver_threshold"].get<double>(), 0.0);
  EXPECT_EQ(separate["sliver_threshold"], inRun["sliver_threshold"]);
  EXPECT_EQ(separate["slivers_merged"], inRun["slivers_merged"]);
  EXPECT_EQ(separate["elements_split"], inRun["elements_split"]);
  const auto provenance = readJson("cut.json")["provenance"];
  EXPECT_EQ(provenance["reference"], "grid_cell");
  EXPECT_EQ(provenance["sliver_fraction"], 0.02);
  // The cut mesh keeps it: `polydg info` reads back the grid cell and the rule.
  ASSERT_EQ(runPolydg("info " + path("c.vtu") + " --quiet --report " + path("i.json")).exitCode, 0);
  const auto info = readJson("i.json");
  EXPECT_EQ(info["provenance_stored"], true);
  EXPECT_EQ(info["provenance"]["cell_size"], provenance["cell_size"]);
  EXPECT_EQ(info["provenance"]["sliver_threshold"], separate["sliver_threshold"]);
  EXPECT_NE(info["provenance"]["source"].get<std::string>().find("torus.obj"), std::string::npos);
}

// --solver auto: Cholesky up to 3000 DOFs, CG with the p-multigrid above.
TEST_F(Commands, SolverAutoPicksByTheNumberOfUnknowns) {
  const std::string small = meshTorus("small.vtu", 4);   // about 60 elements, p = 1: < 3000
  const std::string large = meshTorus("large.vtu", 12);  // about 900 elements, p = 1: > 3000
  for (const auto& [mesh, kind] : {std::pair{small, "cholesky"}, std::pair{large, "cg"}}) {
    const CommandResult r = runPolydg("solve " + mesh + " -o " + path("u.vtu") +
                                      " --degree 1 --clamp-below 0,0,1,0 --gravity 0,0,-1 " +
                                      "--report " + path("s.json") + " --quiet");
    ASSERT_EQ(r.exitCode, 0) << r.out;
    const auto j = readJson("s.json");
    SCOPED_TRACE(j["dofs"].dump());
    EXPECT_EQ(j["solver"]["kind"], kind);
    EXPECT_EQ(j["dofs"].get<std::size_t>() <= 3000, std::string(kind) == "cholesky");
    EXPECT_EQ(j["solver"]["success"], true);
  }
}

// Real models (assimp-testmodels: a human figure, a rock, a torus with a light and cameras, a
// noisy cube, an animated mesh; and the bundled torus), none with a face in a coordinate plane:
// a pipeline clamps each below a tenth of its height (the only way to hold a scan without cutting
// it flat first) and solves every one, its written solution doing the work its energy says.
TEST_F(Commands, APipelineOverRealModelsClampedBelowSolvesEveryOne) {
  const std::string models = "/usr/share/assimp/models/";
  const std::vector<std::string> inputs{models + "BLEND/HUMAN.blend",
                                        models + "3DS/fels.3ds",
                                        models + "BLEND/TorusLightsCams_250_compressed.blend",
                                        models + "BLEND/NoisyTexturedCube_VoronoiGlob_248.blend",
                                        models + "X/anim_test.x",
                                        testData("torus.obj")};
  struct Solved {
    std::string file;
    double energy = 0.0;
    std::size_t elements = 0;
  };
  std::vector<Solved> solved;
  for (const std::string& input : inputs) {
    SCOPED_TRACE(input);
    ASSERT_TRUE(fs::exists(input)) << "install Debian's assimp-testmodels (scripts/setup.sh)";
    const CommandResult info = runPolydg("info " + input + " --quiet --report " + path("i.json"));
    ASSERT_EQ(info.exitCode, 0) << info.out;
    const auto box = readJson("i.json")["bounding_box"];
    const double z0 = box["min"][2].get<double>(), z1 = box["max"][2].get<double>();
    const double below = z0 + 0.1 * (z1 - z0);
    std::ostringstream pipeline;
    pipeline.precision(17);
    pipeline << R"({"steps": [{"step": "mesh", "cells": 12},
      {"step": "solve", "degree": 1, "material": {"E": 1000, "nu": 0.3, "density": 1},
       "gravity": [0, 0, -9.81], "clamp": [{"below": [0, 0, 1, )"
             << below << R"(]}], "estimate": true, "output": "{stem}_solved.vtu"}]})";
    std::ofstream(path("p.json")) << pipeline.str();
    const CommandResult run = runPolydg("run " + path("p.json") + " --inputs " + input + " --out " +
                                        path("runs") + " --quiet --report " + path("r.json"));
    EXPECT_EQ(run.exitCode, 0) << run.out;
    const auto report = readJson("r.json")["inputs"][0];
    ASSERT_EQ(report["status"], "ok") << report["error"];
    const auto& solve = report["steps"][1];
    EXPECT_GT(solve["clamps"][0]["faces"].get<int>(), 0);
    EXPECT_EQ(solve["solver"]["success"], true);
    // Held and solved: the energy the solve reports, 1/2 u.F, is 1/2 u.K u (the estimate's
    // energy norm squared over 2: u solves K u = F; measured at most 6e-12 relative,
    // HUMAN.blend with CHOLMOD), and the written file below must agree with it.
    const double energy = solve["energy"].get<double>();
    EXPECT_GT(energy, 0.0);
    const double norm = solve["estimate"]["energy_norm"].get<double>();
    EXPECT_NEAR(0.5 * norm * norm, energy, 1e-9 * energy);
    const std::string stem = report["stem"].get<std::string>();
    solved.push_back({(dir_ / "runs" / stem / (stem + "_solved.vtu")).string(), energy,
                      report["elements"].get<std::size_t>()});
  }
  // Clapeyron's theorem on each written solution (read once for all, by VTK): the energy is
  // half the work of gravity on the written displacement (F is gravity's load; measured 1.1e-15
  // relative at most).
  std::vector<std::string> files;
  for (const Solved& s : solved) files.push_back(s.file);
  const auto figures = polydg::testing::writtenFigures(files);
  ASSERT_EQ(figures.size(), solved.size()) << figures.dump();
  for (std::size_t i = 0; i < solved.size(); ++i) {
    SCOPED_TRACE(solved[i].file);
    EXPECT_EQ(figures[i]["cells"], solved[i].elements);
    EXPECT_NEAR(polydg::testing::gravityWorkHalf(figures[i], 1.0, {0.0, 0.0, -9.81}),
                solved[i].energy, 1e-12 * solved[i].energy);
  }
}

}  // namespace
