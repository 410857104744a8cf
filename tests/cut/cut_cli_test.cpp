// `polydg cut` as users run it: the report's keys and figures, exit codes, one-line errors, and
// no output (nor a changed input) when an argument or an operation's validation fails.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/support/run_polydg.h"

namespace {

namespace fs = std::filesystem;

using Result = polydg::testing::CommandResult;

Result run(const std::string& arguments) { return polydg::testing::runPolydg(arguments); }

std::size_t lines(const std::string& s) {
  return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

class CutCli : public polydg::testing::CommandTest {
 protected:
  void SetUp() override {
    CommandTest::SetUp();
    // A 4 x 4 x 4 grid of the unit cube (cube.obj spans [0, 1]^3).
    const Result mesh = run("mesh " + polydg::testing::testData("cube.obj") + " --cells 4 -o " +
                            path("cube.vtu") + " --quiet");
    ASSERT_EQ(mesh.exitCode, 0) << mesh.out;
  }
  std::string input() const { return path("cube.vtu"); }
};

TEST_F(CutCli, ReportsEveryOperation) {
  const Result r = run("cut " + input() + " -o " + path("out.vtu") +
                       " --plane 0,0,1,0.3 --plane \"1,1,1,1.4\" --remove-side + --report " +
                       path("r.json") + " --quiet");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  EXPECT_TRUE(r.out.empty()) << r.out;
  ASSERT_TRUE(fs::exists(path("out.vtu")));
  const auto report = readJson("r.json");
  ASSERT_EQ(report["operations"].size(), 2u);
  for (const auto& op : report["operations"]) {
    for (const char* key :
         {"op", "elements_split", "pieces_created", "elements_removed", "volume_removed",
          "slivers_merged", "isolated_slivers", "faces_reintegrated", "faces_total", "left_whole",
          "validation", "time_s"})
      EXPECT_TRUE(op.contains(key)) << key;
    for (const char* key :
         {"passed", "level", "elements_checked", "region_elements", "patch_test_error",
          "region_components", "zero_modes", "volume_rel_error", "failure"})
      EXPECT_TRUE(op["validation"].contains(key)) << key;
    EXPECT_TRUE(op["validation"]["passed"].get<bool>());
    EXPECT_EQ(op["validation"]["level"], "local");
  }
  const auto& first = report["operations"][0];
  EXPECT_EQ(first["op"], "cut");
  EXPECT_EQ(first["elements_split"], 16);  // one layer of the 4^3 grid
  EXPECT_NEAR(first["volume_removed"].get<double>(), 0.7, 1e-12);
  const double removed = first["volume_removed"].get<double>() +
                         report["operations"][1]["volume_removed"].get<double>();
  EXPECT_NEAR(report["input"]["volume"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(report["output"]["volume"].get<double>() + removed, 1.0, 1e-12);
  EXPECT_EQ(report["output"]["components"], 1);
  const Result check = run("check " + path("out.vtu") + " --quiet");
  EXPECT_EQ(check.exitCode, 0) << check.out;
}

TEST_F(CutCli, PolygonSplitsTheCellsInsideAndReportsThoseLeftWhole) {
  // The rectangle [0.1, 0.85] x [0.2, 0.6] at z = 0.4 in the 4^3 grid of cells of 1/4 (the
  // sliced cube numbers them x fastest, then y, then z: cell (i, j, k) is element i + 4 j +
  // 16 k). Its plane crosses layer k = 1; the sections of cells (1, 1) and (2, 1) lie inside it
  // (elements 21 and 22): those two are split; the 10 others of columns 0-3 x rows 0-2 cross its
  // edge and are left whole; the rest are untouched. Removing the side above takes the split
  // cells' upper pieces, 2 x (1/4)^2 x (0.5 - 0.4) = 0.0125, and nothing else.
  const Result r =
      run("cut " + input() + " -o " + path("out.vtu") +
          " --polygon \"0.1,0.2,0.4;0.85,0.2,0.4;0.85,0.6,0.4;0.1,0.6,0.4\" --remove-side + "
          "--report " +
          path("r.json") + " --quiet");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const auto report = readJson("r.json");
  const auto op = report["operations"][0];
  EXPECT_EQ(op["op"], "cut_polygon");
  EXPECT_TRUE(op["validation"]["passed"].get<bool>());
  EXPECT_EQ(op["elements_split"], 2);
  EXPECT_EQ(op["pieces_created"], 4);
  EXPECT_EQ(op["elements_removed"], 2);
  EXPECT_NEAR(op["volume_removed"].get<double>(), 0.0125, 1e-15);
  EXPECT_EQ(op["left_whole"]["count"], 10);
  // The terminal says so too, with --quiet: a warning, not progress.
  EXPECT_NE(r.out.find("operation 1 (polygon"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("10 element(s) at the polygon's edge left whole"), std::string::npos)
      << r.out;
  std::vector<int> whole;
  for (int j = 0; j <= 2; ++j)
    for (int i = 0; i <= 3; ++i)
      if (!(j == 1 && (i == 1 || i == 2))) whole.push_back(i + 4 * j + 16);
  EXPECT_EQ(op["left_whole"]["first_ids"].get<std::vector<int>>(), whole);
  EXPECT_EQ(report["output"]["elements"], 64);  // 64 - 2 split + 4 pieces - 2 removed
  EXPECT_NEAR(report["output"]["volume"].get<double>(), 1.0 - 0.0125, 1e-15);
  EXPECT_EQ(report["output"]["components"], 1);
}

TEST_F(CutCli, BadArgumentsExitTwoWithOneLineAndNoOutput) {
  for (const std::string& args :
       {std::string("--plane 0,0,0,1"), std::string("--plane 0,0,1"),
        std::string("--plane 0,0,x,1"), std::string("--polygon \"0,0,0;1,0,0;2,0,0\""),
        std::string("--plane 0,0,1,0.5 --remove-side up"),
        std::string("--validate all --plane 0,0,1,0.5"), std::string("")}) {
    const Result r = run("cut " + input() + " -o " + path("out.vtu") + " " + args + " --report " +
                         path("r.json"));
    EXPECT_EQ(r.exitCode, 2) << args << ": " << r.out;
    EXPECT_EQ(lines(r.out), 1u) << args << ": " << r.out;
    EXPECT_FALSE(fs::exists(path("out.vtu"))) << args;
    EXPECT_FALSE(fs::exists(path("r.json"))) << args;
  }
  const auto size = fs::file_size(input());
  const Result same = run("cut " + input() + " -o " + input() + " --plane 0,0,1,0.5");
  EXPECT_EQ(same.exitCode, 2) << same.out;
  EXPECT_EQ(fs::file_size(input()), size);
}

TEST_F(CutCli, FailedCheckExitsOneAndWritesNoMesh) {
  // Without sliver merging, the 1e-12 sheet between these planes is split into pieces far too
  // thin for the DG patch test: the second operation fails and is named.
  const Result r = run("cut " + input() + " -o " + path("out.vtu") +
                       " --plane 0.2,0.3,1,0.61 --plane 0.2,0.3,1,0.610000000001 "
                       "--merge-slivers 0 --report " +
                       path("r.json"));
  EXPECT_EQ(r.exitCode, 1) << r.out;
  EXPECT_EQ(lines(r.out), 1u) << r.out;
  EXPECT_NE(r.out.find("operation 2"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(path("out.vtu")));
  const auto report = readJson("r.json");
  EXPECT_FALSE(report["passed"].get<bool>());
  EXPECT_FALSE(report["operations"][1]["validation"]["passed"].get<bool>());
}

}  // namespace
