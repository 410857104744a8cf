// Invariants of the DG discretization over a corpus of small meshes: the patch test (a linear
// field is reproduced by IP), exactly six rigid zero modes per connected component without
// boundary conditions, and a symmetric positive definite matrix with them; on hex grids,
// non-convex prisms (an L and a square with a hole), a grid with a sliver element, and meshes
// translated by 1e6 or scaled by 1e-6 and 1e6. Degrees 1 to 3. The element-local checks pass on
// the same corpus and a sliced sphere, and fail on meshes with a corrupted face or element.
#include "physics/checks/dg_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/task_arena.h>

#include "mesh/primitives.h"
#include "polydg/mesh/geometry_checks.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/shapes.h"

namespace polydg {
namespace {

/// Patch-test tolerance of the issue: reproduction to 1e-9 relative (also per element).
constexpr double kPatchTolerance = 1e-9;
/// Rigid motions must be in the kernel of the Jacobi-scaled matrix to round-off (with the
/// absolute-coordinate floor of a mesh translated by 1e6, see patchTest()).
constexpr double kRigidResidualTolerance = 1e-8;
/// Symmetry of the assembled matrix, relative to its largest entry.
constexpr double kSymmetryTolerance = 1e-12;

struct NamedMesh {
  std::string name;
  PolyMesh mesh;
};

using testing::lPrism;

PolyMesh holePrism() {
  Polygon2 h;
  h.outer = {{0, 0}, {3, 0}, {3, 3}, {0, 3}};
  h.holes = {{{1, 1}, {1, 2}, {2, 2}, {2, 1}}};
  return prismMesh(h, 0.0, 1.0, Vec2(0.25, 0.0));
}

/// A 3 x 3 x 3 grid of the unit cube whose node plane x = 1/3 is moved to x = 1e-6: the first
/// layer of elements are slivers of relative thickness 1e-6.
PolyMesh sliverGrid() {
  PolyMesh mesh = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  for (Vec3& p : mesh.positions().raw())
    if (std::abs(p.x() - 1.0 / 3.0) < 1e-12) p.x() = 1e-6;
  return mesh;
}

PolyMesh transformed(PolyMesh mesh, double scale, const Vec3& offset) {
  transform(mesh, scale, offset);
  return mesh;
}

std::vector<NamedMesh> corpus() {
  const PolyMesh grid = hexGridMesh(3, 2, 2, Box3(Vec3::Zero(), Vec3(1.5, 1.0, 1.0)));
  std::vector<NamedMesh> meshes;
  meshes.push_back({"hex grid", grid});
  meshes.push_back({"L prism", lPrism()});
  meshes.push_back({"prism with hole", holePrism()});
  meshes.push_back({"sliver", sliverGrid()});
  meshes.push_back({"translated 1e6", transformed(grid, 1.0, Vec3(1e6, -1e6, 1e6))});
  meshes.push_back({"scaled 1e-6", transformed(grid, 1e-6, Vec3::Zero())});
  meshes.push_back({"scaled 1e6", transformed(grid, 1e6, Vec3::Zero())});
  meshes.push_back({"L prism scaled 1e-6", transformed(lPrism(), 1e-6, Vec3::Zero())});
  // Two separate blocks: two components, twelve zero modes.
  const PolyMesh two = testing::twoSeparateBlocks();
  meshes.push_back({"two components", two});
  return meshes;
}

class DgChecks : public ::testing::TestWithParam<int> {};

TEST_P(DgChecks, PatchTestReproducesLinearFields) {
  for (const NamedMesh& m : corpus()) {
    ASSERT_TRUE(checkGeometry(m.mesh).passed) << m.name;
    PhysicsCheckOptions options;
    options.discretization.basis.degree = GetParam();
    const PatchTestResult r = patchTest(m.mesh, options);
    EXPECT_LT(r.relativeError, kPatchTolerance) << m.name;
    EXPECT_LT(r.maxElementError, kPatchTolerance) << m.name;
  }
}

TEST_P(DgChecks, SixRigidZeroModesPerComponent) {
  for (const NamedMesh& m : corpus()) {
    PhysicsCheckOptions options;
    options.discretization.basis.degree = GetParam();
    const ZeroModeReport r = rigidModes(m.mesh, options);
    EXPECT_EQ(r.zeroModes, 6 * r.components) << m.name;
    for (std::size_t c = 0; c < r.components; ++c)
      EXPECT_EQ(r.zeroModesPerComponent[c], 6u) << m.name << " component " << c;
    EXPECT_LT(r.largestZeroEigenvalue, 1e-3 * kZeroModeThreshold) << m.name;
    EXPECT_GT(r.smallestNonzeroEigenvalue, 1e3 * kZeroModeThreshold) << m.name;
    EXPECT_LT(r.rigidMotionResidual, kRigidResidualTolerance) << m.name;
  }
  EXPECT_EQ(rigidModes(corpus().back().mesh, {}).components, 2u);
}

TEST_P(DgChecks, ClampedStiffnessIsSymmetricPositiveDefinite) {
  for (const NamedMesh& m : corpus()) {
    for (Method method : {Method::IP, Method::BZ}) {
      PhysicsCheckOptions options;
      options.discretization.basis.degree = GetParam();
      options.discretization.method = method;
      const DefinitenessReport r = definiteness(m.mesh, options);
      EXPECT_LT(r.asymmetry, kSymmetryTolerance) << m.name;
      EXPECT_TRUE(r.choleskySucceeded) << m.name;
      EXPECT_EQ(r.modes.zeroModes, 0u) << m.name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Degrees, DgChecks, ::testing::Values(1, 2, 3),
                         [](const auto& info) { return "p" + std::to_string(info.param); });

TEST(DgChecks, ScaledMonomialBasisPassesThePatchTest) {
  PhysicsCheckOptions options;
  options.discretization.basis = {.degree = 2, .kind = BasisKind::ScaledMonomial};
  EXPECT_LT(patchTest(lPrism(), options).relativeError, kPatchTolerance);
  EXPECT_EQ(rigidModes(lPrism(), options).zeroModes, 6u);
}

TEST(DgChecks, NearlyIncompressiblePatchTestAndRigidModes) {
  PhysicsCheckOptions options;
  options.discretization.basis.degree = 2;
  options.material.poissonRatio = 0.4999;
  const PolyMesh grid = hexGridMesh(2, 2, 2, Box3(Vec3::Zero(), Vec3::Ones()));
  EXPECT_LT(patchTest(grid, options).relativeError, kPatchTolerance);
  EXPECT_EQ(rigidModes(grid, options).zeroModes, 6u);
}

LocalDgCheck localChecks(const PolyMesh& mesh, int degree) {
  MomentCache moments(mesh, 2 * degree);
  moments.update();
  LocalDgCheckOptions options;
  options.basis.degree = degree;
  return localDgChecks(mesh, moments, options);
}

void expectLocalChecksPass(const PolyMesh& mesh, int degree, const std::string& name) {
  const LocalDgCheck c = localChecks(mesh, degree);
  EXPECT_EQ(c.degree, degree) << name;
  EXPECT_EQ(c.elements, mesh.numElements()) << name;
  EXPECT_LT(c.maxPatchTestError, kLocalPatchTestTolerance) << name;
  EXPECT_EQ(c.patchTestFailures, 0u) << name;
  EXPECT_EQ(c.elementsWithWrongRigidModes, 0u) << name;
  EXPECT_FALSE(c.firstWrongRigidModeElement.valid()) << name;
  EXPECT_EQ(c.nonDefiniteElements, 0u) << name;
  EXPECT_TRUE(c.passed()) << name;
}

using testing::withReversedFaces;

/// Index in its element's face list of a boundary face of element e.
int boundaryFaceOf(const PolyMesh& mesh, ElementId e) {
  const Element& element = mesh.element(e);
  for (std::size_t j = 0; j < element.faces.size(); ++j)
    if (mesh.face(element.faces[j].face).isBoundary()) return static_cast<int>(j);
  return -1;
}

TEST_P(DgChecks, LocalChecksPassOnTheCorpus) {
  for (const NamedMesh& m : corpus()) expectLocalChecksPass(m.mesh, GetParam(), m.name);
}

TEST(DgChecks, LocalChecksPassOnASlicedSphere) {
  const TriangleSurface sphere = icosphere(Vec3(0.1, -0.2, 0.05), 1.0, 3);
  const PolyMesh mesh = sliceSurface(sphere, Grid::withCellsAlongLongest(bounds(sphere), 6));
  ASSERT_TRUE(checkGeometry(mesh).passed);
  ASSERT_GT(mesh.numElements(), 100u);
  for (int degree : {1, 2}) expectLocalChecksPass(mesh, degree, "degree " + std::to_string(degree));
}

TEST(DgChecks, LocalChecksAgreeWithTheRewrittenMesh) {
  // The rebuilding helper of the corruption tests changes nothing by itself.
  const PolyMesh grid = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  const PolyMesh same = withReversedFaces(grid, ElementId(), 0);
  ASSERT_TRUE(checkGeometry(same).passed);
  expectLocalChecksPass(same, 1, "rebuilt grid");
}

/// A corrupted mesh fails the local patch test by a wide margin: the errors below are >= 1e-6,
/// the valid corpus above stays below 1e-13.
constexpr double kCorruptionMargin = 1e3;

TEST(DgChecks, LocalChecksFailOnANonPlanarFace) {
  // The centre vertex of a 2 x 2 x 2 grid, moved off the planes of its 12 faces by 1e-3 of an
  // element's size.
  PolyMesh mesh = hexGridMesh(2, 2, 2, Box3(Vec3::Zero(), Vec3::Ones()));
  for (Vec3& p : mesh.positions().raw())
    if ((p - Vec3::Constant(0.5)).norm() < 1e-12) p += Vec3(0.3e-3, 0.2e-3, 0.4e-3);
  EXPECT_FALSE(checkGeometry(mesh).passed);
  for (int degree : {1, 2}) {
    const LocalDgCheck c = localChecks(mesh, degree);
    EXPECT_FALSE(c.passed()) << degree;
    EXPECT_GT(c.maxPatchTestError, kCorruptionMargin * kLocalPatchTestTolerance) << degree;
    EXPECT_EQ(c.patchTestFailures, 8u) << degree;  // every element has the vertex
    EXPECT_TRUE(c.worstPatchTestElement.valid());
  }
}

TEST(DgChecks, LocalChecksFailOnAReversedFace) {
  const PolyMesh grid = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  const ElementId bad(13 - 9);  // on the boundary z = 0, in the middle
  const PolyMesh mesh = withReversedFaces(grid, bad, boundaryFaceOf(grid, bad));
  EXPECT_FALSE(checkGeometry(mesh).passed);
  for (int degree : {1, 2}) {
    const LocalDgCheck c = localChecks(mesh, degree);
    EXPECT_FALSE(c.passed()) << degree;
    EXPECT_GT(c.maxPatchTestError, kCorruptionMargin * kLocalPatchTestTolerance) << degree;
    EXPECT_EQ(c.worstPatchTestElement, bad) << degree;
  }
}

TEST(DgChecks, LocalChecksFailOnAnInvertedElement) {
  // A lone box with every face reversed: negative volume, a negative definite stiffness.
  const PolyMesh mesh =
      withReversedFaces(boxMesh(Box3(Vec3::Zero(), Vec3(1, 2, 3))), ElementId(0), -1);
  EXPECT_FALSE(checkGeometry(mesh).passed);
  const LocalDgCheck c = localChecks(mesh, 1);
  EXPECT_FALSE(c.passed());
  EXPECT_EQ(c.elementsWithWrongRigidModes, 1u);
  EXPECT_EQ(c.firstWrongRigidModeElement, ElementId(0));
}

/// Every k-th element of `mesh`, starting at `first`.
std::vector<char> everyKth(const PolyMesh& mesh, std::size_t k, std::size_t first) {
  std::vector<char> only(mesh.numElements(), 0);
  for (std::size_t e = first; e < only.size(); e += k) only[e] = 1;
  return only;
}

TEST(DgChecks, LocalChecksOfASelectionEqualThoseOnTheWholeMesh) {
  // Moments of the selection and its neighbours only give the very numbers of the whole mesh.
  const TriangleSurface sphere = icosphere(Vec3(0.1, -0.2, 0.05), 1.0, 3);
  const PolyMesh mesh = sliceSurface(sphere, Grid::withCellsAlongLongest(bounds(sphere), 6));
  ASSERT_GT(mesh.numElements(), 100u);
  for (int degree : {1, 2}) {
    MomentCache moments(mesh, 2 * degree);
    moments.update();
    LocalDgCheckOptions options;
    options.basis.degree = degree;
    options.only = everyKth(mesh, 5, 2);
    const LocalDgCheck whole = localDgChecks(mesh, moments, options);
    const LocalDgCheck selection = localDgChecksOfSelection(mesh, options);
    EXPECT_EQ(selection.elements, whole.elements) << degree;
    EXPECT_GT(selection.elements, 20u) << degree;
    EXPECT_EQ(selection.maxPatchTestError, whole.maxPatchTestError) << degree;
    EXPECT_EQ(selection.worstPatchTestElement, whole.worstPatchTestElement) << degree;
    EXPECT_TRUE(selection.passed()) << degree;
  }
}

TEST(DgChecks, LocalChecksOfASelectionNameTheCorruptedElement) {
  const PolyMesh grid = hexGridMesh(3, 3, 3, Box3(Vec3::Zero(), Vec3::Ones()));
  const ElementId bad(13 - 9);  // on the boundary z = 0, in the middle
  const PolyMesh mesh = withReversedFaces(grid, bad, boundaryFaceOf(grid, bad));
  LocalDgCheckOptions options;
  options.only = everyKth(mesh, 2, 0);  // elements 0, 2, 4, ...: 4 is the corrupted one
  const LocalDgCheck c = localDgChecksOfSelection(mesh, options);
  EXPECT_EQ(c.elements, 14u);
  EXPECT_FALSE(c.passed());
  EXPECT_GT(c.maxPatchTestError, kCorruptionMargin * kLocalPatchTestTolerance);
  EXPECT_EQ(c.worstPatchTestElement, bad);
  // Left out, the corrupted element is only a neighbour: its linear trace is still exact.
  options.only = everyKth(mesh, 2, 1);
  EXPECT_TRUE(localDgChecksOfSelection(mesh, options).passed());
}

TEST(DgChecks, LocalChecksOfASelectionInPartsEqualThoseOnTheWholeMesh) {
  // More elements than localDgChecksOfSelection() copies and checks at a time (1024): the
  // parts give the numbers of the whole mesh, and name a corrupted element of the third part
  // by its id in the mesh.
  const PolyMesh grid = hexGridMesh(14, 14, 14, Box3(Vec3::Zero(), Vec3::Ones()));
  const ElementId bad(14 * 14 * 14 - 100);
  ASSERT_GE(boundaryFaceOf(grid, bad), 0);
  const PolyMesh mesh = withReversedFaces(grid, bad, boundaryFaceOf(grid, bad));
  MomentCache moments(mesh, 2);
  moments.update();
  LocalDgCheckOptions options;
  options.only.assign(mesh.numElements(), 1);
  const LocalDgCheck whole = localDgChecks(mesh, moments, options);
  const LocalDgCheck parts = localDgChecksOfSelection(mesh, options);
  EXPECT_EQ(parts.elements, mesh.numElements());
  EXPECT_EQ(parts.patchTestFailures, 1u);
  EXPECT_EQ(parts.worstPatchTestElement, bad);
  EXPECT_EQ(parts.maxPatchTestError, whole.maxPatchTestError);
  EXPECT_EQ(parts.worstPatchTestElement, whole.worstPatchTestElement);
  EXPECT_EQ(parts.nonDefiniteElements, whole.nonDefiniteElements);
  EXPECT_EQ(parts.elementsWithWrongRigidModes, whole.elementsWithWrongRigidModes);
  // On one thread, each part is copied right after the one before it, which shares faces and
  // vertices with it.
  tbb::task_arena oneThread(1);
  const LocalDgCheck serial =
      oneThread.execute([&] { return localDgChecksOfSelection(mesh, options); });
  EXPECT_EQ(serial.patchTestFailures, 1u);
  EXPECT_EQ(serial.worstPatchTestElement, bad);
  EXPECT_EQ(serial.maxPatchTestError, whole.maxPatchTestError);
}

}  // namespace
}  // namespace polydg
