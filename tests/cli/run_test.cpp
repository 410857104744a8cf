// polydg run as users run it: the example pipeline end to end (outputs, reports, the cut
// operations as `polydg cut` reports them, outputs that `polydg check` accepts, solutions whose
// energy is half the work of their load), a batch in
// which some inputs are broken (a missing file, an open surface) while the others succeed, VTU
// inputs, and pipeline files refused up front with one line naming the bad key or step.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "tests/support/run_polydg.h"
#include "tests/support/written_figures.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// Volumes of the example pipeline's outputs: the unit cube less the slab z < 0.1 is 0.9 (the
/// cut is exact, so only round-off separates them).
constexpr double kVolumeTolerance = 1e-12;

using Result = polydg::testing::CommandResult;

Result run(const std::string& arguments) { return polydg::testing::runPolydg(arguments); }

std::string data(const std::string& name) { return polydg::testing::testData(name); }

class Run : public polydg::testing::CommandTest {
 protected:
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  /// Names in folder `name` (files and folders).
  std::vector<std::string> listing(const std::string& name) const {
    std::vector<std::string> out;
    for (const auto& entry : fs::directory_iterator(path(name)))
      out.push_back(entry.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
};

/// Exit 2 and one line naming `what`.
void expectRefused(const Result& r, const std::string& what) {
  EXPECT_EQ(r.exitCode, 2) << r.out;
  EXPECT_NE(r.out.find(what), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
}

/// The line of the summary table for `input` (empty if none).
std::string summaryLine(const std::string& out, const std::string& input) {
  const std::size_t table = out.rfind("\ninput ");
  if (table == std::string::npos) return {};
  std::size_t at = out.find(input, table);
  if (at == std::string::npos) return {};
  at = out.rfind('\n', at) + 1;
  return out.substr(at, out.find('\n', at) - at);
}

TEST_F(Run, ExamplePipeline) {
  const Result r = run("run " + data("pipeline.json") + " --out " + path("out") + " --report " +
                       path("summary.json"));
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_EQ(listing("out"), (std::vector<std::string>{"cube", "torus"}));
  for (const std::string stem : {"torus", "cube"}) {
    std::vector<std::string> files{"report.json", stem + ".vtu", stem + "_solution.vtu"};
    std::sort(files.begin(), files.end());
    EXPECT_EQ(listing("out/" + stem), files);
    const json report = readJson("out/" + stem + "/report.json");
    EXPECT_EQ(report["status"], "ok") << stem;
    EXPECT_TRUE(report["error"].is_null());
    const json& steps = report["steps"];
    ASSERT_EQ(steps.size(), 6u) << stem;
    const std::vector<std::string> names{"mesh", "cut", "cut", "check", "solve", "write"};
    for (std::size_t k = 0; k < names.size(); ++k) {
      EXPECT_EQ(steps[k]["step"], names[k]);
      EXPECT_GE(steps[k]["time_s"].get<double>(), 0.0);
    }
    for (int k : {1, 2}) {
      const json& op = steps[k]["operations"][0];
      EXPECT_EQ(op["op"], "cut");
      EXPECT_GT(op["elements_split"].get<int>(), 0) << stem << k;
      EXPECT_GE(op["pieces_created"].get<int>(), op["elements_split"].get<int>());
      EXPECT_TRUE(op["validation"]["passed"]) << stem << k;
      EXPECT_GT(op["faces_reintegrated"].get<int>(), 0);
      EXPECT_LT(op["faces_reintegrated"].get<int>(), op["faces_total"].get<int>());
      EXPECT_TRUE(op.contains("slivers_merged"));
      EXPECT_TRUE(op.contains("time_s"));
    }
    EXPECT_GT(steps[1]["operations"][0]["elements_removed"].get<int>(), 0);
    // Trimmed, then split in two decoupled components: 12 rigid modes.
    const json& check = steps[3]["validation"];
    EXPECT_TRUE(check["passed"]) << stem;
    EXPECT_EQ(check["rigid_modes_global"], 12) << stem;
    EXPECT_LT(check["patch_test_error"].get<double>(), 1e-9);
    EXPECT_GT(steps[4]["dirichlet_faces"].get<int>(), 0);
    // The written solution against the solve's energy: Clapeyron's theorem, energy = half the
    // work of gravity (0, 0, -1) on density 1, from the file's cells (to 1e-15 measured).
    const auto figures =
        polydg::testing::writtenFigures(path("out/" + stem + "/" + stem + "_solution.vtu"));
    ASSERT_FALSE(figures.is_null());
    EXPECT_EQ(figures["cells"], steps[4]["elements"]);
    const double energy = steps[4]["energy"].get<double>();
    EXPECT_GT(energy, 0.0);
    EXPECT_NEAR(polydg::testing::gravityWorkHalf(figures, 1.0, {0.0, 0.0, -1.0}), energy,
                1e-12 * energy)
        << stem;
    EXPECT_EQ(report["elements"], steps[5]["elements"]);
    // The written mesh is valid for `polydg check` and has the reported volume.
    const Result c = run("check " + path("out/" + stem + "/" + stem + ".vtu") + " --report " +
                         path(stem + "_check.json"));
    EXPECT_EQ(c.exitCode, 0) << c.out;
    const json cj = readJson(stem + "_check.json");
    EXPECT_NEAR(cj["volume"].get<double>(), report["volume"].get<double>(),
                kVolumeTolerance * report["volume"].get<double>());
    EXPECT_EQ(cj["components"], 2);
  }
  EXPECT_NEAR(readJson("out/cube/report.json")["volume"].get<double>(), 0.9, kVolumeTolerance);
  const json summary = readJson("summary.json");
  EXPECT_EQ(summary["failed"], 0);
  EXPECT_TRUE(summary["passed"]);
  ASSERT_EQ(summary["inputs"].size(), 2u);
  EXPECT_NE(summaryLine(r.out, "cube.obj").find(" ok "), std::string::npos) << r.out;
  EXPECT_NE(summaryLine(r.out, "torus.obj").find(" ok "), std::string::npos) << r.out;
}

/// A light pipeline for batches: mesh at 6 cells, trim, check, write.
const char* kBatchPipeline = R"({
  "steps": [
    {"step": "mesh", "cells": 6},
    {"step": "cut", "plane": [0, 0, 1, 0.1], "remove_side": "-", "validate": "local"},
    {"step": "merge", "fraction": 0.01},
    {"step": "check"},
    {"step": "write", "path": "meshes/{stem}_trimmed.vtu"}
  ]
})";

TEST_F(Run, BrokenInputsFailAloneAndTheOthersSucceed) {
  const std::string pipeline = write("batch.json", kBatchPipeline);
  // An open surface: the unit cube without its top.
  const std::string open =
      write("open.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
            "f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
  const std::string missing = path("missing.obj");
  for (int jobs : {1, 2}) {
    const std::string out = "out" + std::to_string(jobs);
    const Result r =
        run("run " + pipeline + " --inputs " + data("cube.obj") + " " + missing + " " + open + " " +
            data("torus.obj") + " " + data("cube.obj") + " --jobs " + std::to_string(jobs) +
            " --out " + path(out) + " --report " + path(out + ".json"));
    EXPECT_EQ(r.exitCode, 1) << r.out;
    // Every input has its folder, nothing is left half-written, a repeated stem gets _2.
    EXPECT_EQ(listing(out),
              (std::vector<std::string>{"cube", "cube_2", "missing", "open", "torus"}))
        << r.out;
    for (const std::string stem : {"cube", "cube_2", "torus"}) {
      EXPECT_EQ(listing(out + "/" + stem), (std::vector<std::string>{"meshes", "report.json"}));
      EXPECT_EQ(listing(out + "/" + stem + "/meshes"),
                (std::vector<std::string>{(stem == "cube_2" ? "cube_2" : stem) + "_trimmed.vtu"}));
      EXPECT_EQ(readJson(out + "/" + stem + "/report.json")["status"], "ok") << stem;
    }
    for (const std::string stem : {"missing", "open"}) {
      EXPECT_EQ(listing(out + "/" + stem), std::vector<std::string>{"report.json"});
      const json report = readJson(out + "/" + stem + "/report.json");
      EXPECT_EQ(report["status"], "failed");
      EXPECT_FALSE(report["error"].get<std::string>().empty());
    }
    EXPECT_NE(readJson(out + "/open/report.json")["error"].get<std::string>().find("step 0 (mesh)"),
              std::string::npos);
    // The summary lists the failures with their first error, the successes as ok.
    EXPECT_NE(summaryLine(r.out, missing).find("FAILED"), std::string::npos) << r.out;
    EXPECT_NE(summaryLine(r.out, open).find("FAILED"), std::string::npos) << r.out;
    EXPECT_NE(summaryLine(r.out, open).find("closed"), std::string::npos) << r.out;
    EXPECT_NE(summaryLine(r.out, data("torus.obj")).find(" ok "), std::string::npos) << r.out;
    const json summary = readJson(out + ".json");
    EXPECT_EQ(summary["failed"], 2);
    EXPECT_NEAR(summary["inputs"][0]["volume"].get<double>(), 0.9, kVolumeTolerance);
    const json& merge = summary["inputs"][0]["steps"][2];
    EXPECT_EQ(merge["step"], "merge");
    EXPECT_EQ(merge["operations"][0]["op"], "merge");
    EXPECT_TRUE(merge["operations"][0]["validation"]["passed"]);
    EXPECT_EQ(summary["inputs"][0]["elements"], summary["inputs"][4]["elements"]);
  }
  // Concurrency changes nothing in the results.
  for (int i = 0; i < 5; ++i) {
    const json a = readJson("out1.json")["inputs"][i], b = readJson("out2.json")["inputs"][i];
    EXPECT_EQ(a["status"], b["status"]);
    EXPECT_EQ(a["elements"], b["elements"]);
    EXPECT_EQ(a["volume"], b["volume"]);
  }
}

TEST_F(Run, ASolverFailureLeavesOnlyTheReport) {
  // The cut along x = 0.5 decouples the half x > 0.5 of the cube, which no clamp holds: the
  // stiffness is singular. The mesh written before the solve does not stay behind.
  const std::string pipeline = write("solve.json", R"({"steps": [
    {"step": "mesh", "cells": 4},
    {"step": "cut", "plane": [1, 0, 0, 0.5]},
    {"step": "write", "path": "{stem}.vtu"},
    {"step": "solve", "clamp": [{"axis": "x", "value": 0}], "output": "{stem}_u.vtu"}]})");
  const Result r =
      run("run " + pipeline + " --inputs " + data("cube.obj") + " --out " + path("out"));
  EXPECT_EQ(r.exitCode, 1) << r.out;
  EXPECT_EQ(listing("out/cube"), std::vector<std::string>{"report.json"});
  const json report = readJson("out/cube/report.json");
  EXPECT_EQ(report["status"], "failed");
  const std::string error = report["error"];
  EXPECT_NE(error.find("step 3 (solve)"), std::string::npos) << error;
  EXPECT_NE(error.find("not positive definite"), std::string::npos) << error;
  EXPECT_NE(error.find("is every piece of the body held"), std::string::npos) << error;
  EXPECT_EQ(report["steps"].size(), 4u);
  EXPECT_EQ(report["steps"][3]["error"], error.substr(error.find(": ") + 2));
  EXPECT_NE(summaryLine(r.out, "cube.obj").find("FAILED"), std::string::npos) << r.out;
}

TEST_F(Run, SimulationMeshInputsSkipTheMeshStep) {
  ASSERT_EQ(
      run("mesh " + data("cube.obj") + " --cells 4 -o " + path("cube4.vtu") + " --quiet").exitCode,
      0);
  const std::string pipeline = write("batch.json", kBatchPipeline);
  const Result r = run("run " + pipeline + " --inputs " + path("cube4.vtu") + " --out " +
                       path("out") + " --quiet");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_TRUE(r.out.empty()) << r.out;
  const json report = readJson("out/cube4/report.json");
  EXPECT_EQ(report["steps"][0]["step"], "read");
  EXPECT_EQ(report["steps"][1]["step"], "cut");
  EXPECT_NEAR(report["volume"].get<double>(), 0.9, kVolumeTolerance);
  EXPECT_TRUE(fs::exists(path("out/cube4/meshes/cube4_trimmed.vtu")));
  // The cut is reported with the keys of `polydg cut`'s report, and the same figures.
  const Result cut =
      run("cut " + path("cube4.vtu") + " -o " + path("cut.vtu") +
          " --plane 0,0,1,0.1 --remove-side - --report " + path("cut.json") + " --quiet");
  ASSERT_EQ(cut.exitCode, 0) << cut.out;
  const json a = readJson("cut.json")["operations"][0], b = report["steps"][1]["operations"][0];
  const auto keys = [](const json& j) {
    std::vector<std::string> k;
    for (const auto& [key, value] : j.items()) k.push_back(key);
    return k;
  };
  EXPECT_EQ(keys(a), keys(b));
  EXPECT_EQ(keys(a["validation"]), keys(b["validation"]));
  for (const char* key : {"elements_split", "pieces_created", "elements_removed", "faces_total"})
    EXPECT_EQ(a[key], b[key]) << key;
  // An input inside the folder its run would replace is refused before anything is written.
  fs::copy_file(path("cube4.vtu"), path("out/cube4/cube4.vtu"));
  const Result inside = run("run " + pipeline + " --inputs " + path("out/cube4/cube4.vtu") +
                            " --out " + path("out/../out") + " --quiet");
  expectRefused(inside, "lies in the output folder");
  EXPECT_TRUE(fs::exists(path("out/cube4/cube4.vtu")));
  EXPECT_TRUE(fs::exists(path("out/cube4/meshes/cube4_trimmed.vtu")));
  // The same pipeline with --quiet and a failure: one line on stderr, exit 1.
  const Result bad = run("run " + pipeline + " --inputs " + path("nothing.vtu") + " --out " +
                         path("out") + " --quiet");
  EXPECT_EQ(bad.exitCode, 1) << bad.out;
  EXPECT_EQ(std::count(bad.out.begin(), bad.out.end(), '\n'), 1) << bad.out;
  EXPECT_NE(bad.out.find("nothing.vtu"), std::string::npos) << bad.out;
}

TEST_F(Run, InvalidPipelinesAreRefusedUpFront) {
  const std::string inputs = " --inputs " + data("cube.obj") + " --out " + path("out");
  expectRefused(run("run " + write("a.json", "{\"steps\": [") + inputs), "not valid JSON");
  expectRefused(run("run " + write("b.json", R"({"steps": [{"step": "slice"}]})") + inputs),
                "steps[0].step: 'slice' is not one of");
  expectRefused(run("run " + write("c.json", R"({"steps": [{"step": "mesh", "cells": 4},
      {"step": "cut", "plnae": [0, 0, 1, 0]}]})") +
                    inputs),
                "steps[1]: a cut needs exactly one of");
  expectRefused(run("run " + write("d.json", R"({"steps": [{"step": "mesh", "cells": 4,
      "cels": 3}]})") +
                    inputs),
                "steps[0].cels: unknown key");
  expectRefused(run("run " + write("e.json", R"({"step": []})") + inputs),
                "pipeline.steps: missing");
  expectRefused(run("run " + write("f.json", R"({"steps": [{"step": "mesh", "cells": 4},
      {"step": "write", "path": "../escape.vtu"}]})") +
                    inputs),
                "steps[1].path: '..'");
  expectRefused(run("run " + write("g.json", R"({"steps": [{"step": "mesh", "cells": 4},
      {"step": "cut", "plane": [0, 0, 0, 1]}]})") +
                    inputs),
                "steps[1].plane");
  expectRefused(run("run " + write("h.json", R"({"steps": [{"step": "mesh", "cells": 4},
      {"step": "solve", "material": {"nu": 0.7}, "clamp": [{"axis": "z", "value": 0}]}]})") +
                    inputs),
                "steps[1].material.nu");
  expectRefused(
      run("run " +
          write("i.json", R"({"steps": [{"step": "check"}, {"step": "mesh", "cells": 4}]})") +
          inputs),
      "steps[1]: the mesh step must be the first step");
  expectRefused(
      run("run " + write("j.json", R"({"steps": [{"step": "check"}]})") + " --out " + path("out")),
      "no inputs");
  EXPECT_FALSE(fs::exists(path("out")));
}

}  // namespace
