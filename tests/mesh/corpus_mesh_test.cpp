// Every model of the assimp-testmodels corpus either meshes (closed ones directly, broken ones
// with --repair wrap) into a valid simulation mesh, or is refused with a one-line error naming
// the problem: no crash, no hang (ctest's timeout), no invalid mesh.
#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <map>

#include "polydg/mesh/meshing.h"
#include "polydg/mesh/surface_io.h"
#include "tests/support/assimp_models.h"
#include "tests/support/packages.h"

namespace polydg {
namespace {

namespace fs = std::filesystem;

/// Coarse grid: the corpus run checks robustness, not resolution.
constexpr int kCells = 8;

enum class Outcome { Direct, Wrapped, Unreadable, Refused };

struct Result {
  Outcome outcome;
  std::string detail;
  std::size_t elements = 0;
};

bool oneLine(const std::string& s) { return !s.empty() && s.find('\n') == std::string::npos; }

Result meshModel(const std::string& path) {
  TriangleSurface surface;
  try {
    surface = readSurface(path);
  } catch (const std::runtime_error& e) {
    return {Outcome::Unreadable, e.what()};
  }
  MeshingOptions options;
  options.cellsAlongLongest = kCells;
  try {
    const MeshingResult r = meshSurface(surface, options);
    EXPECT_TRUE(r.report.validation.passed) << path;
    return {Outcome::Direct, "", r.report.elements};
  } catch (const InputError& refused) {
    const std::string why = refused.what();
    EXPECT_TRUE(oneLine(why)) << path << ": " << why;
    EXPECT_TRUE(why.find("open (") != std::string::npos ||
                why.find("non-manifold (") != std::string::npos ||
                why.find("self-intersecting (") != std::string::npos ||
                why.find("degenerate") != std::string::npos ||
                why.find("no volume") != std::string::npos)
        << path << ": the refusal names no defect: " << why;
    options.repair = RepairMode::Wrap;
    try {
      const MeshingResult r = meshSurface(surface, options);
      EXPECT_TRUE(r.report.validation.passed) << path << " (wrapped)";
      return {Outcome::Wrapped, refused.what(), r.report.elements};
    } catch (const InputError& e) {
      return {Outcome::Refused, e.what()};
    }
  }
}

TEST(CorpusMeshing, EveryModelMeshesOrIsRefusedWithOneLine) {
  ASSERT_TRUE(packages::assimpTestModels());
  std::vector<fs::path> models;
  for (const auto& entry : fs::recursive_directory_iterator(corpus::kAssimpModels))
    if (entry.is_regular_file() && corpus::isSupportedModel(entry.path()))
      models.push_back(entry.path());
  std::sort(models.begin(), models.end());
  std::map<Outcome, std::size_t> counts;
  for (const fs::path& model : models) {
    std::cout << "  " << fs::relative(model, corpus::kAssimpModels).string() << " ..." << std::endl;
    const auto start = std::chrono::steady_clock::now();
    const Result r = meshModel(model.string());
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++counts[r.outcome];
    const char* what[] = {"meshed", "meshed after wrap", "unreadable", "refused"};
    std::cout << "  " << fs::relative(model, corpus::kAssimpModels).string() << ": "
              << what[static_cast<int>(r.outcome)];
    if (r.elements) std::cout << ", " << r.elements << " elements";
    if (!r.detail.empty()) std::cout << " (" << r.detail << ")";
    std::cout << ", " << seconds << " s" << std::endl;
    if (r.outcome == Outcome::Unreadable || r.outcome == Outcome::Refused) {
      EXPECT_TRUE(oneLine(r.detail)) << model;
    }
  }
  std::cout << models.size() << " models: " << counts[Outcome::Direct] << " meshed directly, "
            << counts[Outcome::Wrapped] << " after --repair wrap, " << counts[Outcome::Refused]
            << " refused, " << counts[Outcome::Unreadable] << " unreadable\n";
  // Today's run (2026-11-23): 153 meshed directly, 123 after wrap, 1 refused (one degenerate
  // triangle), 88 unreadable. The bounds catch a pipeline that starts refusing or failing
  // good models; the refusals of the 15 closed models that needed wrap name a defect
  // (self-intersections), checked per model above.
  EXPECT_GE(counts[Outcome::Direct], 150u);
  EXPECT_GE(counts[Outcome::Wrapped], 120u);
  EXPECT_LE(counts[Outcome::Refused], 1u);
}

}  // namespace
}  // namespace polydg
