// Pipelines through the library: the steps of one input share one model, so each face is
// integrated once however many steps read the moments; pipeline files are checked strictly.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "polydg/mesh/surface_shapes.h"
#include "polydg/model/pipeline.h"

namespace polydg {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("polydg_pipeline_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// A torus written as OBJ (the pipeline reads files, as users give them).
  std::string torusFile() {
    const TriangleSurface t = torus(Vec3::Zero(), 1.0, 0.4, 40, 20);
    const fs::path path = dir_ / "torus.obj";
    std::ofstream out(path);
    out.precision(17);
    for (const Vec3& v : t.vertices) out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    for (const auto& f : t.triangles)
      out << "f " << f[0] + 1 << ' ' << f[1] + 1 << ' ' << f[2] + 1 << '\n';
    return path.string();
  }
  fs::path dir_;
};

TEST_F(PipelineTest, EachFaceIsIntegratedOnceThroughAllSteps) {
  const json document = json::parse(R"({
    "steps": [
      {"step": "mesh", "cells": 8},
      {"step": "cut", "plane": [1, 0.25, 0.5, 0.125], "remove_side": "+"},
      {"step": "cut", "polygon": [[-2, -2, 0.1], [2, -2, 0.1], [2, 0.5, 0.1], [-2, 0.5, 0.1]]},
      {"step": "merge"},
      {"step": "check", "degree": 2},
      {"step": "solve", "degree": 2, "clamp": [{"below": [0, 0, 1, -0.2]}],
       "gravity": [0, 0, -1], "output": "{stem}_solved.vtu"},
      {"step": "check", "degree": 1},
      {"step": "write", "path": "{stem}.vtu"}
    ]})");
  const Pipeline pipeline = parsePipeline(document, "test.json", dir_);
  EXPECT_EQ(pipeline.momentDegree(), 4);
  const InputOutcome o = runPipelineInput(pipeline, torusFile(), "torus", dir_ / "out");
  ASSERT_TRUE(o.passed) << o.error;
  const json& steps = o.report["steps"];
  ASSERT_EQ(steps.size(), 8u);
  // Meshing integrates the new mesh once, to degree 4; each edit integrates what it made or
  // changed; the checks and the solve integrate nothing.
  std::size_t expected = steps[0]["faces_integrated"].get<std::size_t>();
  EXPECT_EQ(expected, steps[0]["output"]["faces"].get<std::size_t>());
  for (std::size_t k : {1, 2, 3}) {
    const std::size_t edited = steps[k]["operations"][0]["faces_reintegrated"].get<std::size_t>();
    if (k < 3) {
      EXPECT_GT(edited, 0u) << steps[k].dump();
    }
    expected += edited;
  }
  EXPECT_EQ(steps[4]["validation"]["faces_integrated"], 0);
  EXPECT_EQ(steps[5]["faces_integrated"], 0);
  EXPECT_EQ(steps[6]["validation"]["faces_integrated"], 0);
  EXPECT_EQ(o.facesIntegrated, expected);
  EXPECT_EQ(o.report["faces_integrated"], expected);
  EXPECT_TRUE(fs::exists(dir_ / "out" / "torus" / "torus_solved.vtu"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "torus" / "torus.vtu"));
}

TEST_F(PipelineTest, AVtuInputIsIntegratedOnceToTheDegreeItsStepsNeed) {
  const std::string torus = torusFile();
  const Pipeline meshOnly = parsePipeline(
      json::parse(
          R"({"steps": [{"step": "mesh", "cells": 6}, {"step": "write", "path": "m.vtu"}]})"),
      "a.json", dir_);
  ASSERT_TRUE(runPipelineInput(meshOnly, torus, "torus", dir_ / "a").passed);
  const Pipeline steps = parsePipeline(json::parse(R"({"steps": [
      {"step": "cut", "plane": [0, 1, 0, 0.3]},
      {"step": "solve", "degree": 3, "clamp": [{"box": [[-2, -2, -2], [2, 2, -0.3]]}]}]})"),
                                       "b.json", dir_);
  const InputOutcome o =
      runPipelineInput(steps, (dir_ / "a" / "torus" / "m.vtu").string(), "m", dir_ / "b");
  ASSERT_TRUE(o.passed) << o.error;
  const json& read = o.report["steps"][0];
  EXPECT_EQ(read["step"], "read");
  EXPECT_EQ(read["provenance_restored"], true);
  EXPECT_EQ(read["faces_integrated"], read["faces"]);  // once, to degree 6
  EXPECT_EQ(o.facesIntegrated,
            read["faces_integrated"].get<std::size_t>() +
                o.report["steps"][1]["operations"][0]["faces_reintegrated"].get<std::size_t>());
}

TEST_F(PipelineTest, ErrorsNameTheFileAndThePlace) {
  const auto refused = [&](const std::string& text) -> std::string {
    try {
      parsePipeline(json::parse(text), "p.json", dir_);
    } catch (const InputError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(refused(R"({"steps": [{"step": "cut", "plnae": [0, 0, 1, 0]}]})").substr(0, 32),
            "p.json: steps[0]: a cut needs ex");
  EXPECT_NE(
      refused(R"({"steps": [{"step": "check", "degre": 2}]})").find("steps[0].degre: unknown key"),
      std::string::npos);
  EXPECT_NE(refused(R"({"steps": [{"step": "solve", "clamp": [{"below": [0, 0, 1]}]}]})")
                .find("steps[0].clamp[0].below: expected 4 finite numbers"),
            std::string::npos);
  EXPECT_NE(
      refused(
          R"({"steps": [{"step": "solve", "clamp": [{"below": [0, 0, 1, 0], "box": [[0,0,0],[1,1,1]]}]}]})")
          .find("give exactly one region"),
      std::string::npos);
  EXPECT_NE(refused(R"({"steps": [{"step": "solve", "clamp": [{"box": [[1,0,0],[0,1,1]]}]}]})")
                .find("steps[0].clamp[0]: the box's first corner"),
            std::string::npos);
  EXPECT_NE(refused(R"({"steps": [{"step": "mesh", "cells": 4}, {"step": "mesh", "cells": 4}]})")
                .find("steps[1]: the mesh step must be the first step"),
            std::string::npos);
  // Values are the options' own checks (DiscretizationOptions, Material, SolveOptions), named
  // at their keys: the rule a solve applies is the rule the file is read by.
  const std::string clamp = R"("clamp": [{"below": [0, 0, 1, 0]}])";
  const std::vector<std::pair<std::string, std::string>> values = {
      {R"({"step": "check", "degree": 4})", "p.json: steps[0].degree: must be 1, 2 or 3"},
      {R"({"step": "solve", "degree": 0, )" + clamp + "}", "steps[0].degree: must be 1, 2 or 3"},
      {R"({"step": "solve", "penalty": "fixed", )" + clamp + "}",
       "steps[0].eta: a fixed penalty needs its eta"},
      {R"({"step": "solve", "eta": -1, )" + clamp + "}", "steps[0].eta: the penalty must be"},
      {R"({"step": "solve", "bz_penalty": "super", )" + clamp + "}", "steps[0].bz_penalty: "},
      {R"({"step": "solve", "material": {"E": 0}, )" + clamp + "}",
       "steps[0].material.E: Young's modulus must be a positive number"},
      {R"({"step": "solve", "material": {"nu": 0.6}, )" + clamp + "}", "steps[0].material.nu: "},
      {R"({"step": "solve", "estimate": true, "method": "bz", )" + clamp + "}",
       "steps[0].estimate: the error estimate is for the IP method"},
      {R"({"step": "solve"})", "steps[0].clamp: nothing holds the body"},
  };
  for (const auto& [step, message] : values) {
    const std::string got = refused(R"({"steps": [)" + step + "]}");
    EXPECT_NE(got.find(message), std::string::npos) << step << "\n -> " << got;
  }
}

}  // namespace
}  // namespace polydg
