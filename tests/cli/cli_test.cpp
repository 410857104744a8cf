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

namespace {

namespace fs = std::filesystem;

/// Relative agreement of our enclosed volume with VTK's vtkMassProperties.
constexpr double kVolumeAgreement = 1e-9;

struct Result {
  int exitCode = -1;
  std::string out;  // stdout and stderr together
};

Result run(const std::string& arguments) {
  const std::string command = std::string(POLYDG_BINARY) + " " + arguments + " 2>&1";
  Result r;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) r.out += buffer.data();
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string data(const std::string& name) { return std::string(POLYDG_TESTDATA_DIR) + "/" + name; }

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("polydg_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::size_t filesInDir() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  }
  nlohmann::json readJson(const std::string& name) const {
    std::ifstream in(path(name));
    return nlohmann::json::parse(in);
  }
  fs::path dir_;
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
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "no /usr/bin/python3 for VTK";
  const std::string script = std::string(POLYDG_SOURCE_DIR) + "/tests/mesh/surface_volume.py";
  for (const std::string& model :
       {data("torus.obj"), data("octahedron.stl"), data("Lprism.ply"), data("two_cubes.obj"),
        std::string("/usr/share/assimp/models/PLY/cube_binary.ply")}) {
    if (!fs::exists(model)) continue;
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
  for (const char* key : {"vertices", "triangles", "closed", "self_intersecting", "volume", "repairs"})
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
  // The mesh never overwrites its input.
  const Result self = run("mesh " + data("torus.obj") + " --cells 4 -o " + data("torus.obj"));
  EXPECT_EQ(self.exitCode, 2);
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

}  // namespace
