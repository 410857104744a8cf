// Tests of mesh/surface_io.h: the testdata models read with exact counts, closure, volumes and
// areas; welding, degenerate and point/line handling; one-line errors; no crash and no output
// over assimp's own test models; agreement with VTK's volumes (tests/mesh/surface_volume.py).
#include "mesh/surface_io.h"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace polydg {
namespace {

namespace fs = std::filesystem;

/// Volumes and areas of the testdata models are exact (dyadic coordinates) up to round-off.
constexpr double kExactRelTol = 1e-12;
/// VTK's volume against polydg's: the tolerance the CLI test uses.
constexpr double kVtkRelTol = 1e-9;
/// Address space allowed while reading foreign or corrupt files (see AddressSpaceCap).
constexpr rlim_t kReadAddressSpace = rlim_t{4} << 30;

const fs::path kAssimpModels = "/usr/share/assimp/models";
const fs::path kSystemPython = "/usr/bin/python3";

std::string testdata(const std::string& name) {
  return (fs::path(POLYDG_TESTDATA_DIR) / name).string();
}

fs::path volumeScript() {
  return fs::path(POLYDG_TESTDATA_DIR).parent_path() / "tests" / "mesh" / "surface_volume.py";
}

double relativeError(double value, double exact) {
  return std::abs(value - exact) / std::abs(exact);
}

/// A fresh directory under the system temp dir, removed when the test ends.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(fs::temp_directory_path() /
              ("polydg_surface_io_" + name + "_" + std::to_string(getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    std::ofstream(file) << text;
    return file.string();
  }

 private:
  fs::path path_;
};

/// Caps this process's address space for its lifetime, so that a reader allocating what a
/// corrupt header declares fails with std::bad_alloc instead of exhausting the machine's memory
/// (assimp's invalid/OutOfMemory.off made an uncapped assimp take 16 GB).
class AddressSpaceCap {
 public:
  explicit AddressSpaceCap(rlim_t bytes) {
    getrlimit(RLIMIT_AS, &saved_);
    rlimit cap = saved_;
    if (cap.rlim_cur == RLIM_INFINITY || cap.rlim_cur > bytes) cap.rlim_cur = bytes;
    setrlimit(RLIMIT_AS, &cap);
  }
  ~AddressSpaceCap() { setrlimit(RLIMIT_AS, &saved_); }
  AddressSpaceCap(const AddressSpaceCap&) = delete;
  AddressSpaceCap& operator=(const AddressSpaceCap&) = delete;

 private:
  rlimit saved_{};
};

/// The message of the std::runtime_error that reading `path` throws ("" if it reads).
std::string readError(const std::string& path) {
  try {
    readSurface(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// --- the testdata models ----------------------------------------------------------------------

struct ModelCase {
  std::string file;
  std::size_t meshes, polygons, vertices, triangles, components;
  double volume, area;
};

void PrintTo(const ModelCase& c, std::ostream* os) { *os << c.file; }

class TestModel : public testing::TestWithParam<ModelCase> {};

TEST_P(TestModel, ReadsClosedWithExactCountsVolumeAndArea) {
  const ModelCase& c = GetParam();
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(testdata(c.file), &info);
  EXPECT_EQ(s.vertices.size(), c.vertices);
  EXPECT_EQ(s.triangles.size(), c.triangles);
  EXPECT_EQ(info.meshes, c.meshes);
  EXPECT_EQ(info.polygons, c.polygons);
  EXPECT_EQ(info.fannedPolygons, 0u);
  EXPECT_EQ(info.weldedVertices, c.vertices);
  EXPECT_EQ(info.triangles, c.triangles);
  EXPECT_GE(info.inputVertices, c.vertices);
  EXPECT_EQ(info.droppedDegenerate, 0u);
  EXPECT_EQ(info.ignoredPoints, 0u);
  EXPECT_EQ(info.ignoredLines, 0u);

  const SurfaceTopology topo = analyzeTopology(s);
  EXPECT_TRUE(topo.closed()) << topo.boundaryEdges << " boundary, " << topo.nonManifoldEdges
                             << " non-manifold, " << topo.misorientedEdges << " misoriented edges";
  EXPECT_EQ(topo.components, c.components);
  EXPECT_EQ(topo.degenerateTriangles, 0u);
  // The volume is positive only if the file's outward winding survived; the area (sum of
  // unsigned triangle areas) exceeds the exact one if a non-convex face was triangulated with
  // overlapping triangles, which the signed volume would not notice.
  EXPECT_LT(relativeError(enclosedVolume(s), c.volume), kExactRelTol) << enclosedVolume(s);
  EXPECT_LT(relativeError(surfaceArea(s), c.area), kExactRelTol) << surfaceArea(s);
}

INSTANTIATE_TEST_SUITE_P(
    Testdata, TestModel,
    testing::Values(
        // Unit cube of six quads: 24 OBJ corners weld to 8 vertices, quads become 12 triangles.
        ModelCase{"cube.obj", 1, 6, 8, 12, 1, 1.0, 6.0},
        // Octahedron (+-1, 0, 0), (0, +-2, 0), (0, 0, +-3): volume 4/3 * 1 * 2 * 3, eight faces
        // of area 7/2 each. Some zeros are written -0, so the weld must treat -0.0 as 0.0.
        ModelCase{"octahedron.stl", 1, 0, 6, 8, 1, 8.0, 28.0},
        // Tetrahedron with legs 2, 3, 4 along the axes: volume 2 * 3 * 4 / 6; right faces of
        // area 3, 4 and 6 and a slanted one of area |(12, 8, 6)| / 2 = sqrt(61).
        ModelCase{"tetra.off", 1, 0, 4, 4, 1, 4.0, 13.0 + std::sqrt(61.0)},
        // L-shaped hexagon of area 3 extruded to height 1.5: two non-convex hexagons (4
        // triangles each) and six quads; area 2 * 3 + perimeter 8 * 1.5. (assimp 5.2.5's
        // aiProcess_Triangulate gets the top hexagon wrong: area 19.)
        ModelCase{"Lprism.ply", 1, 8, 12, 20, 1, 4.5, 18.0},
        // Cubes of volume 1 and 8 in two objects; the second cube is split over the two
        // materials (meshes), so it is closed only if vertices weld across meshes.
        ModelCase{"two_cubes.obj", 2, 12, 16, 24, 2, 9.0, 30.0},
        // One unit-cube mesh used by two glTF nodes (one scaled by 2) under a translated root:
        // closed with two components only if node transforms are baked per instance.
        ModelCase{"instanced_cubes.gltf", 1, 0, 16, 24, 2, 9.0, 30.0}),
    [](const testing::TestParamInfo<ModelCase>& info) {
      std::string name = info.param.file;
      for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return name;
    });

TEST(ReadSurface, WeldsStlCornersIncludingNegativeZero) {
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(testdata("octahedron.stl"), &info);
  EXPECT_EQ(info.inputVertices, 24u);  // STL repeats every corner
  ASSERT_EQ(s.vertices.size(), 6u);
  for (const Vec3& p : s.vertices)
    for (int i = 0; i < 3; ++i) EXPECT_FALSE(p[i] == 0.0 && std::signbit(p[i])) << p.transpose();
}

TEST(ReadSurface, BakesNodeTransformsOfInstancedMeshes) {
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(testdata("instanced_cubes.gltf"), &info);
  EXPECT_EQ(info.inputVertices, 16u);  // the 8-vertex mesh once per node
  // Root translation (0, 0, 1); instances [0,1]^3 + (-2, 0, 0) and 2 * [0,1]^3 + (3, 0, 0).
  const Box3 box = bounds(s);
  EXPECT_EQ(box.min(), Vec3(-2, 0, 1));
  EXPECT_EQ(box.max(), Vec3(5, 2, 3));
}

TEST(ReadSurface, DropsOnlyTrianglesWithRepeatedVertices) {
  // The tetrahedron of tetra.off, plus vertex 5 = vertex 1 written as (-0, -0, 0), vertex 6 on
  // edge 1-2, a triangle 1 5 2 that welding makes degenerate and a zero-area triangle 1 6 2
  // with three distinct vertices, which is kept.
  const TempDir dir("weld");
  const std::string path = dir.write("weld.obj",
                                     "v 0 0 0\nv 2 0 0\nv 0 3 0\nv 0 0 4\nv -0 -0 0\nv 1 0 0\n"
                                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 5 2\nf 1 6 2\n");
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.droppedDegenerate, 1u);
  EXPECT_EQ(info.triangles, 5u);
  EXPECT_EQ(s.triangles.size(), 5u);
  EXPECT_EQ(s.vertices.size(), 5u);  // vertex 5 welded into vertex 1
  const SurfaceTopology topo = analyzeTopology(s);
  EXPECT_EQ(topo.degenerateTriangles, 1u);  // the zero-area triangle
  EXPECT_EQ(topo.nonManifoldEdges, 1u);     // edge 1-2, now used three times
  EXPECT_EQ(topo.boundaryEdges, 2u);        // edges 1-6 and 6-2
  EXPECT_LT(relativeError(enclosedVolume(s), 4.0), kExactRelTol);
}

TEST(ReadSurface, SkipsAndCountsPointsAndLinesBesideTriangles) {
  std::ifstream cube(testdata("cube.obj"));
  const std::string text((std::istreambuf_iterator<char>(cube)), std::istreambuf_iterator<char>());
  const TempDir dir("mixed");
  // Two points and a polyline of two segments.
  const std::string path = dir.write("mixed.obj", text + "p 1 2\nl 1 2 3\n");
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.ignoredPoints, 2u);
  EXPECT_EQ(info.ignoredLines, 2u);
  EXPECT_EQ(s.triangles.size(), 12u);
  EXPECT_EQ(s.vertices.size(), 8u);
  EXPECT_TRUE(analyzeTopology(s).closed());
}

TEST(ReadSurface, FansPolygonsThatHaveNoExactTriangulation) {
  // A self-crossing quad (a bow tie) and four collinear corners (zero area).
  const TempDir dir("fan");
  const std::string path = dir.write("fan.obj",
                                     "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n"
                                     "v 0 0 5\nv 1 0 5\nv 2 0 5\nv 3 0 5\nf 5 6 7 8\n");
  SurfaceReadInfo info;
  const TriangleSurface s = readSurface(path, &info);
  EXPECT_EQ(info.polygons, 2u);
  EXPECT_EQ(info.fannedPolygons, 2u);
  EXPECT_EQ(s.triangles.size(), 4u);
  EXPECT_EQ(analyzeTopology(s).degenerateTriangles, 2u);  // the collinear fan
}

// --- errors -----------------------------------------------------------------------------------

TEST(ReadSurfaceErrors, MissingFile) {
  const std::string path = testdata("no_such_model.obj");
  EXPECT_EQ(readError(path), path + ": no such file");
}

TEST(ReadSurfaceErrors, Directory) {
  const std::string path = POLYDG_TESTDATA_DIR;
  EXPECT_EQ(readError(path), path + ": is a directory; give the path of a mesh file");
}

TEST(ReadSurfaceErrors, UnknownFormatQuotesAssimpOnOneLine) {
  const TempDir dir("unknown");
  const std::string path = dir.write("notes.xyz", "hello\nworld\n");
  const std::string message = readError(path);
  EXPECT_EQ(message.rfind(path + ": assimp cannot read it (", 0), 0u) << message;
  EXPECT_NE(message.find("No suitable reader"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(ReadSurfaceErrors, HeaderCountsLargerThanTheFile) {
  const AddressSpaceCap cap(kReadAddressSpace);
  const TempDir dir("counts");
  const std::string off =
      dir.write("faces.off", "OFF\n# corrupt face count\n3 4000000000 0\n0 0 0\n1 0 0\n0 1 0\n"
                             "3 0 1 2\n");
  EXPECT_EQ(readError(off), off + ": header declares 4000000000 faces but the file has only " +
                                std::to_string(fs::file_size(off)) + " bytes; the file is corrupt");
  const std::string ply = dir.write(
      "faces.ply",
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1500000000\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(readError(ply), ply + ": header declares 1500000000 'face' elements but the file "
                                  "has only " + std::to_string(fs::file_size(ply)) +
                                " bytes; the file is corrupt");
}

TEST(ReadSurfaceErrors, OnlyPointsOrLines) {
  const TempDir dir("points");
  const std::string expected = ": contains only points/lines, no triangles; polydg needs a "
                               "surface mesh";
  const std::string points = dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2\np 3\n");
  EXPECT_EQ(readError(points), points + expected);
  const std::string lines = dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n");
  EXPECT_EQ(readError(lines), lines + expected);
  const std::string cloud = dir.write("cloud.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  EXPECT_EQ(readError(cloud), cloud + expected);
}

TEST(ReadSurfaceErrors, SceneWithoutMeshes) {
  const TempDir dir("nomesh");
  const std::string path = dir.write(
      "empty.gltf", R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}]})");
  EXPECT_EQ(readError(path), path + ": contains no meshes");
}

TEST(ReadSurfaceErrors, OnlyDegenerateTriangles) {
  const TempDir dir("degenerate");
  const std::string path = dir.write("flat.obj", "v 0 0 0\nv 0 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(readError(path), path + ": no face has three distinct vertices (1 degenerate); "
                                    "polydg needs a surface mesh");
}

TEST(ReadSurfaceErrors, NonFiniteCoordinate) {
  const TempDir dir("nonfinite");
  for (const char* value : {"inf", "nan"}) {
    const std::string path = dir.write(std::string(value) + ".obj", std::string("v ") + value +
                                                                       " 0 0\nv 1 0 0\nv 0 1 0\n"
                                                                       "f 1 2 3\n");
    EXPECT_EQ(readError(path),
              path + ": a vertex has a non-finite coordinate (NaN or infinity); fix the file");
  }
}

/// Reads every regular file under `root` whose name passes `wanted`, in sorted order, with the
/// address space capped; returns per file "closed", "open" or "error: <message>". Fails the
/// test on any exception other than a one-line std::runtime_error naming the file, and if
/// reading printed anything to stdout or stderr.
std::map<std::string, std::string> readAll(const fs::path& root, bool (*wanted)(const fs::path&)) {
  std::vector<std::string> paths;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    if (entry.is_regular_file() && wanted(entry.path())) paths.push_back(entry.path().string());
  std::map<std::string, std::string> outcome;
  const AddressSpaceCap cap(kReadAddressSpace);
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  for (const std::string& path : paths) {
    try {
      outcome[path] = analyzeTopology(readSurface(path)).closed() ? "closed" : "open";
    } catch (const std::runtime_error& e) {
      outcome[path] = std::string("error: ") + e.what();
    } catch (const std::exception& e) {
      outcome[path] = std::string("unexpected exception: ") + e.what();
    }
  }
  const std::string printed =
      testing::internal::GetCapturedStdout() + testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed, "") << "reading files under " << root << " printed output";
  for (auto& [path, what] : outcome) {
    EXPECT_EQ(what.rfind("unexpected", 0), std::string::npos) << path << ": " << what;
    if (what.rfind("error: ", 0) != 0) continue;
    const std::string message = what.substr(7);
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
    what = "error: " + message.substr(std::min(message.size(), path.size() + 2));
  }
  return outcome;
}

TEST(ReadSurfaceErrors, AssimpInvalidModelsFailCleanly) {
  const fs::path dir = kAssimpModels / "invalid";
  if (!fs::is_directory(dir)) GTEST_SKIP() << dir << " is missing (install assimp-testmodels)";
  const auto outcome = readAll(dir, [](const fs::path&) { return true; });
  ASSERT_FALSE(outcome.empty());
  for (const auto& [path, what] : outcome) {
    const std::string name = fs::path(path).filename().string();
    std::cout << "  " << name << ": " << what << "\n";
    // Empty files, out-of-range face indices and absurd counts cannot make a surface.
    if (name.starts_with("empty") || name == "malformed.obj" || name == "OutOfMemory.off") {
      EXPECT_TRUE(what.starts_with("error: ")) << path;
    }
  }
}

TEST(ReadSurface, PrintsNothing) {
  // Readable models and each kind of error; assimp's corpus is checked the same way below.
  const TempDir dir("quiet");
  std::vector<std::string> paths;
  for (const char* name : {"cube.obj", "octahedron.stl", "tetra.off", "Lprism.ply",
                           "two_cubes.obj", "instanced_cubes.gltf", "no_such_model.obj"})
    paths.push_back(testdata(name));
  paths.push_back(dir.write("points.obj", "v 0 0 0\nv 1 0 0\np 1 2\n"));
  paths.push_back(dir.write("broken.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"));
  paths.push_back(dir.write("notes.xyz", "hello\n"));
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  for (const std::string& path : paths) readError(path);
  const std::string out = testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
}

// --- assimp's test models ---------------------------------------------------------------------

bool isSupportedModel(const fs::path& path) {
  static const std::set<std::string> kExtensions = {
      "obj", "stl", "ply", "off", "gltf", "glb", "3ds", "dae", "fbx", "x",   "ase", "lwo",
      "ms3d", "md2", "md3", "mdl", "blend", "ac", "3mf", "amf", "ifc", "nff", "raw", "smd",
      "xgl", "irrmesh", "cob", "q3o", "q3s", "ter", "hmp", "lws", "csm", "b3d"};
  std::string name = path.filename().string();
  for (char& ch : name) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (name.size() > 9 && name.ends_with(".mesh.xml")) return true;  // Ogre XML
  const std::size_t dot = name.rfind('.');
  return dot != std::string::npos && kExtensions.contains(name.substr(dot + 1));
}

TEST(AssimpModels, EveryModelReadsOrFailsWithOneLine) {
  if (!fs::is_directory(kAssimpModels))
    GTEST_SKIP() << kAssimpModels << " is missing (install assimp-testmodels)";
  const auto outcome = readAll(kAssimpModels, isSupportedModel);
  std::size_t closed = 0, open = 0, errors = 0;
  for (const auto& [path, what] : outcome) {
    std::cout << "  " << fs::relative(path, kAssimpModels).string() << ": " << what << "\n";
    closed += what == "closed";
    open += what == "open";
    errors += what.rfind("error", 0) == 0;
  }
  std::cout << outcome.size() << " models: " << closed << " closed, " << open << " open, "
            << errors << " errors\n";
  EXPECT_EQ(closed + open + errors, outcome.size());
  // Known outcomes, one per kind, so that a reader that fails everything cannot pass.
  const auto expect = [&](const char* model, const std::string& what) {
    const auto it = outcome.find((kAssimpModels / model).string());
    ASSERT_NE(it, outcome.end()) << model;
    EXPECT_EQ(it->second.substr(0, what.size()), what) << model;
  };
  expect("OBJ/box.obj", "closed");
  expect("glTF2/BoxTextured-glTF-Binary/BoxTextured.glb", "closed");
  expect("STL/triangle.stl", "open");
  expect("PLY/points.ply", "error: contains only points/lines");
  expect("invalid/malformed.obj", "error: assimp cannot read it (");
}

// --- VTK's independent volume -----------------------------------------------------------------

/// Runs tests/mesh/surface_volume.py on `path`; returns its exit status and its stdout.
std::pair<int, std::string> vtkVolume(const std::string& path) {
  const std::string command = kSystemPython.string() + " '" + volumeScript().string() + "' '" +
                              path + "' 2>/dev/null";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, ""};
  std::string out;
  std::array<char, 256> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) out += buffer.data();
  const int status = pclose(pipe);
  return {status, out};
}

bool haveVtk() {
  const std::string command =
      kSystemPython.string() + " -c 'import vtkmodules.vtkFiltersCore' >/dev/null 2>&1";
  return fs::exists(kSystemPython) && std::system(command.c_str()) == 0;
}

TEST(VolumeScript, AgreesWithExactAndReadVolumes) {
  if (!haveVtk()) GTEST_SKIP() << kSystemPython << " cannot import VTK (install python3-vtk9)";
  // Testdata models in VTK's formats, against their exact volumes.
  const std::vector<std::pair<std::string, double>> exact = {
      {"cube.obj", 1.0}, {"octahedron.stl", 8.0}, {"Lprism.ply", 4.5}, {"two_cubes.obj", 9.0}};
  for (const auto& [name, volume] : exact) {
    const auto [status, out] = vtkVolume(testdata(name));
    ASSERT_EQ(status, 0) << name;
    EXPECT_LT(relativeError(std::stod(out), volume), kVtkRelTol) << name << ": " << out;
  }
  // Closed models of assimp's corpus whose faces are planar, so that VTK's triangulation and
  // readSurface's give the same volume: VTK's volume against readSurface's.
  if (fs::is_directory(kAssimpModels)) {
    for (const char* model : {"OBJ/box.obj", "OBJ/cube_usemtl.obj", "OBJ/testmixed.obj",
                              "PLY/cube.ply", "PLY/cube_binary.ply"}) {
      const std::string path = (kAssimpModels / model).string();
      const TriangleSurface s = readSurface(path);
      ASSERT_TRUE(analyzeTopology(s).closed()) << model;
      const auto [status, out] = vtkVolume(path);
      ASSERT_EQ(status, 0) << model;
      EXPECT_LT(relativeError(std::stod(out), enclosedVolume(s)), kVtkRelTol) << model;
    }
  }
  // Failures: a format the script does not handle, and a file VTK reads no polygons from.
  EXPECT_NE(vtkVolume(testdata("tetra.off")).first, 0);
  const TempDir dir("vtk");
  EXPECT_NE(vtkVolume(dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n")).first, 0);
}

}  // namespace
}  // namespace polydg
