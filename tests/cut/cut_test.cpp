// Plane cuts in place: degenerate positions of the plane (through vertices, along edges, in
// existing faces, grazing a vertex), repeated and nearly coincident cuts, removal of either
// side, finite polygon blades, and incremental moments against moments from scratch.
#include "cut/cut.h"

#include <gtest/gtest.h>

#include "mesh/primitives.h"
#include "mesh/validate.h"

namespace polydg {
namespace {

/// Volumes, moments and balances of valid meshes agree to round-off.
constexpr double kVolumeTolerance = 1e-12;
constexpr double kMomentTolerance = 1e-12;

PolyMesh unitGrid(int n) { return hexGridMesh(n, n, n, Box3(Vec3(0, 0, 0), Vec3(1, 1, 1))); }

/// The mesh is valid, its volume is `volume`, and the editor's moments equal fresh ones.
void expectConsistent(const MeshEditor& editor, double volume) {
  const PolyMesh& mesh = editor.mesh();
  const ValidationReport report = validate(mesh);
  ASSERT_TRUE(report.passed) << (report.messages.empty() ? "" : report.messages.front());
  EXPECT_NEAR(report.volume, volume, kVolumeTolerance * volume);
  EXPECT_NEAR(editor.volume(), volume, kVolumeTolerance * volume);
  MomentCache fresh(mesh, editor.moments().degree());
  fresh.update();
  const MomentCache& cached = editor.moments();
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    const auto a = fresh.element(ElementId(e)), b = cached.element(ElementId(e));
    const double scale = std::abs(a[0]);
    for (std::size_t i = 0; i < a.size(); ++i)
      ASSERT_NEAR(a[i], b[i], kMomentTolerance * std::max(scale, std::abs(a[i])))
          << "element " << e << " moment " << i;
  }
}

std::size_t countCutFaces(const PolyMesh& mesh) {
  std::size_t n = 0;
  for (const Face& f : mesh.faces()) n += f.origin == FaceOrigin::Cut;
  return n;
}

TEST(Cut, ObliquePlaneSplitsCrossedElements) {
  MeshEditor editor(unitGrid(4));
  CutOptions options;
  options.sliverFraction = 0.0;
  const auto r = editor.cut(Blade::plane(Vec3(1, 2, 3), 2.9), options);
  EXPECT_TRUE(r.validation.passed) << r.validation.failure;
  EXPECT_GT(r.elementsSplit, 0u);
  EXPECT_GE(r.piecesCreated, 2 * r.elementsSplit);
  EXPECT_EQ(editor.mesh().numElements(), 64 - r.elementsSplit + r.piecesCreated);
  EXPECT_LT(r.facesReintegrated, r.facesTotal);
  expectConsistent(editor, 1.0);
  std::size_t components = 0;
  connectedComponents(editor.mesh(), components);
  EXPECT_EQ(components, 2u);
}

}  // namespace
}  // namespace polydg
