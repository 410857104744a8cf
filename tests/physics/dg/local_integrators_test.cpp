// The DG basis and local integrators: orthonormal bases, element stiffness with the rigid
// motions in its kernel and the energy of a known strain, face matrices that fit together
// symmetrically, exact face quadrature on non-convex faces with holes, and the penalty
// threshold's independence of scale and material.
#include "physics/dg/local_integrators.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "mesh/primitives.h"
#include "physics/dg/assembly.h"
#include "physics/dg/face_quadrature.h"
#include "polydg/mesh/slice.h"
#include "polydg/mesh/surface_shapes.h"
#include "tests/support/shapes.h"

namespace polydg {
namespace {

constexpr double kTolerance = 1e-12;

using testing::lPrism;

class LocalIntegrators : public ::testing::TestWithParam<int> {};

TEST_P(LocalIntegrators, OrthonormalBasisHasIdentityMass) {
  const PolyMesh mesh = lPrism();
  MomentCache moments(mesh, 2 * GetParam());
  moments.update();
  const DgBasis basis(mesh, moments, {.degree = GetParam()});
  Eigen::MatrixXd mass;
  elementMass(basis, moments, ElementId(0), mass);
  EXPECT_LT((mass - Eigen::MatrixXd::Identity(basis.size(), basis.size())).norm(), kTolerance);
  EXPECT_EQ(basis.fallbackElements(), 0u);
}

TEST_P(LocalIntegrators, StiffnessAnnihilatesRigidMotionsAndMeasuresStrainEnergy) {
  const PolyMesh mesh = lPrism();
  const int p = GetParam();
  MomentCache moments(mesh, 2 * p);
  moments.update();
  const DgBasis basis(mesh, moments, {.degree = p, .kind = BasisKind::ScaledMonomial});
  const double mu = 0.7, lambda = 1.3;
  Eigen::MatrixXd k;
  elementStiffness(basis, moments, ElementId(0), mu, lambda, k);
  const int n = basis.size();
  const double h = basis.scale(ElementId(0));
  // With the scaled monomial basis phi_1..3 = (x - c)/h: u = h * e_d x_k has coefficient h.
  auto linear = [&](int d, int axis) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * n);
    u[d * n + 1 + axis] = h;  // u_d = x_axis - c_axis
    return u;
  };
  for (int d = 0; d < 3; ++d) {
    Eigen::VectorXd t = Eigen::VectorXd::Zero(3 * n);
    t[d * n] = 1.0;
    EXPECT_LT((k * t).norm(), kTolerance * k.norm()) << "translation " << d;
  }
  // Rotations about each axis: u = e_a x_b - e_b x_a.
  for (auto [a, b] : {std::pair{0, 1}, std::pair{0, 2}, std::pair{1, 2}}) {
    const Eigen::VectorXd r = linear(a, b) - linear(b, a);
    EXPECT_LT((k * r).norm(), kTolerance * k.norm());
  }
  // u = (x, 0, 0): eps = e1 e1^T, energy int sigma:eps = (2 mu + lambda) vol.
  const Eigen::VectorXd stretch = linear(0, 0);
  EXPECT_NEAR(stretch.dot(k * stretch), (2 * mu + lambda) * 1.5, 1e-12);
  // u = (y, x, 0): eps_12 = 1, energy 4 mu vol... sigma:eps = 2 mu * 2 = 4 mu.
  const Eigen::VectorXd shear = linear(0, 1) + linear(1, 0);
  EXPECT_NEAR(shear.dot(k * shear), 4 * mu * 1.5, 1e-12);
}

TEST_P(LocalIntegrators, FaceBlocksOfBothSidesAreTransposes) {
  const int p = GetParam();
  const PolyMesh mesh = hexGridMesh(2, 1, 1, Box3(Vec3::Zero(), Vec3(2.0, 1.0, 0.5)));
  MomentCache moments(mesh, 2 * p);
  moments.update();
  const DgBasis basis(mesh, moments, {.degree = p});
  const FaceRoles roles = classifyFaces(mesh, {});
  FaceId shared;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f)
    if (roles.kind[FaceId(f)] == FaceKind::Interior) shared = FaceId(f);
  ASSERT_TRUE(shared.valid());
  const FaceUses& u = roles.uses[shared];
  const FormCoefficients form{Method::IP, 0.5, 2.0, 10.0};
  auto view = [&](int s) {
    FaceView v;
    v.face = shared;
    v.self = u.element[s];
    v.other = u.element[1 - s];
    v.selfIsFront = !u.reversed[s];
    v.selfCoupledFaces = v.otherCoupledFaces = 1;
    return v;
  };
  Eigen::MatrixXd s0, o0, s1, o1;
  faceRows(mesh, basis, moments, view(0), form, s0, o0);
  faceRows(mesh, basis, moments, view(1), form, s1, o1);
  EXPECT_LT((s0 - s0.transpose()).norm(), kTolerance * s0.norm());
  EXPECT_LT((s1 - s1.transpose()).norm(), kTolerance * s1.norm());
  EXPECT_LT((o0 - o1.transpose()).norm(), kTolerance * o0.norm());
}

TEST_P(LocalIntegrators, PenaltyThresholdIsScaleAndPositionInvariant) {
  const int p = GetParam();
  PolyMesh mesh = lPrism();
  LoadCase clamp;
  clamp.dirichlet.push_back({FaceSelector::allBoundary(), {}});
  auto threshold = [&](const PolyMesh& m) {
    MomentCache moments(m, 2 * p);
    moments.update();
    const DgBasis basis(m, moments, {.degree = p});
    return penaltyThreshold(m, basis, moments, classifyFaces(m, clamp));
  };
  const double reference = threshold(mesh);
  EXPECT_GT(reference, 0.0);
  transform(mesh, 1e-6, Vec3(1.0, -2.0, 3.0));
  EXPECT_NEAR(threshold(mesh), reference, 1e-9 * reference);
}

INSTANTIATE_TEST_SUITE_P(Degrees, LocalIntegrators, ::testing::Values(1, 2, 3),
                         [](const auto& info) { return "p" + std::to_string(info.param); });

// At degree 1 faceRows() builds the blocks from outer products (constant gradients, constant
// lifting functions): they must be the matrix products' blocks for every method, term group
// and side, on the faces of a sliced ball far from the origin (surface pieces and cut sides).
TEST(LocalIntegrators, DegreeOneOuterProductsGiveTheMatrixProductsBlocks) {
  const TriangleSurface ball = icosphere(Vec3(1e3, -2e3, 5e2), 1.0, 2);
  const PolyMesh mesh = sliceSurface(ball, Grid::withCellsAlongLongest(bounds(ball), 3));
  ASSERT_GT(mesh.numElements(), 10u);
  MomentCache moments(mesh, 2);
  moments.update();
  const DgBasis basis(mesh, moments, {.degree = 1});
  LoadCase clamp;
  clamp.dirichlet.push_back({FaceSelector::allBoundary(), {}});
  const FaceRoles roles = classifyFaces(mesh, clamp);
  ElementData<double> eta(mesh.numElements(), 0.0), area(mesh.numElements(), 0.0);
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    eta[ElementId(e)] = 3.0 + 0.1 * static_cast<double>(e % 7);
    area[ElementId(e)] = 0.01 * (1.0 + static_cast<double>(e % 3));
  }
  FormCoefficients ip{Method::IP, 0.7, 2.3, 11.0}, perElement = ip, bz{Method::BZ, 0.7, 2.3, 5.0},
                                                   bzMean = bz;
  perElement.elementEta = &eta;
  perElement.elementFaceArea = &area;
  bz.bzFactor = 4.0;
  bzMean.bzFactor = 4.0;
  bzMean.bzFactorOnMean = true;
  std::size_t interior = 0, boundary = 0;
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const FaceId face(f);
    const FaceUses& uses = roles.uses[face];
    const FaceKind kind = roles.kind[face];
    (kind == FaceKind::Interior ? interior : boundary) += 1;
    for (int s = 0; s < (kind == FaceKind::Interior ? 2 : 1); ++s) {
      FaceView view;
      view.face = face;
      view.kind = kind;
      view.self = uses.element[s];
      view.selfIsFront = !uses.reversed[s];
      view.selfCoupledFaces = 5 + s;
      if (kind == FaceKind::Interior) {
        view.other = uses.element[1 - s];
        view.otherCoupledFaces = 9;
      }
      for (const FormCoefficients* form : {&ip, &perElement, &bz, &bzMean})
        for (int terms = 1; terms <= kAllFaceTerms; ++terms)
          for (bool withOther : {true, false}) {
            Eigen::MatrixXd self, other, selfRef, otherRef;
            faceRows(mesh, basis, moments, view, *form, self, other, withOther, terms);
            detail::faceRowsByMatrixProducts(mesh, basis, moments, view, *form, selfRef, otherRef,
                                             withOther, terms);
            ASSERT_EQ(self.rows(), selfRef.rows());
            ASSERT_EQ(other.rows(), otherRef.rows());
            EXPECT_LE((self - selfRef).norm(), 1e-12 * selfRef.norm())
                << "face " << f << " side " << s << " terms " << terms;
            if (otherRef.size() > 0) {
              EXPECT_LE((other - otherRef).norm(), 1e-12 * otherRef.norm())
                  << "face " << f << " side " << s << " terms " << terms;
            }
          }
    }
  }
  EXPECT_GT(interior, 20u);
  EXPECT_GT(boundary, 20u);
}

// faceUses() and classifyFaces() run on both cores; what they give must be what one pass over
// the elements in order gives: each face's users in element order with their orientations,
// the counts of each kind, and per element the faces with terms. A sliced ball of a few
// thousand elements (many per task) with a region clamp and a traction.
TEST(FaceUses, EachFaceListsItsElementsInOrderAndEachKindIsCounted) {
  const TriangleSurface ball = icosphere(Vec3(3.0, -1.0, 2.0), 1.0, 3);
  const PolyMesh mesh = sliceSurface(ball, Grid::withCellsAlongLongest(bounds(ball), 18));
  ASSERT_GT(mesh.numElements(), 3000u);
  LoadCase loads;
  loads.dirichlet.push_back({FaceSelector::below(Plane::make(Vec3(0, 0, 1), 1.6)), {}});
  loads.tractions.push_back({FaceSelector::below(Plane::make(Vec3(1, 0, 0), 3.5)), Vec3(0, 0, -1)});
  const FaceRoles roles = classifyFaces(mesh, loads);

  std::vector<std::vector<std::pair<ElementId, bool>>> expected(mesh.numFaces());
  for (std::size_t e = 0; e < mesh.numElements(); ++e)
    for (const FaceUse& use : mesh.element(ElementId(e)).faces)
      expected[use.face.index()].emplace_back(ElementId(e), use.reversed);
  std::size_t interior = 0, dirichlet = 0, traction = 0;
  const double diagonal = meshBounds(mesh).diagonal().norm();
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const FaceId face(f);
    const FaceUses& u = roles.uses[face];
    ASSERT_EQ(u.count, static_cast<int>(expected[f].size())) << "face " << f;
    for (int s = 0; s < u.count; ++s) {
      EXPECT_EQ(u.element[s], expected[f][s].first) << "face " << f << " use " << s;
      EXPECT_EQ(u.reversed[s], expected[f][s].second) << "face " << f << " use " << s;
    }
    FaceKind kind = FaceKind::Free;
    if (u.count == 2) {
      kind = FaceKind::Interior;
      ++interior;
    } else if (selects(loads.dirichlet[0].where, mesh, face, diagonal)) {
      kind = FaceKind::Dirichlet;
      ++dirichlet;
    } else if (selects(loads.tractions[0].where, mesh, face, diagonal)) {
      EXPECT_EQ(roles.traction[face], 0) << "face " << f;
      ++traction;
    }
    EXPECT_EQ(roles.kind[face], kind) << "face " << f;
  }
  EXPECT_EQ(roles.interiorFaces, interior);
  EXPECT_EQ(roles.dirichletFaces, dirichlet);
  EXPECT_EQ(roles.tractionFaces, traction);
  EXPECT_GT(dirichlet, 100u);
  EXPECT_GT(traction, 100u);
  for (std::size_t e = 0; e < mesh.numElements(); ++e) {
    int coupled = 0;
    for (const FaceUse& use : mesh.element(ElementId(e)).faces)
      coupled +=
          roles.kind[use.face] == FaceKind::Interior || roles.kind[use.face] == FaceKind::Dirichlet;
    EXPECT_EQ(roles.coupledFaces[ElementId(e)], coupled) << "element " << e;
  }
}

// A face used a third time, or twice the same way, is refused with the face's id, also when
// the wrong use is far from the first (the elements are split among tasks).
TEST(FaceUses, AFaceUsedThreeTimesOrTwiceTheSameWayIsNamed) {
  const PolyMesh grid = hexGridMesh(16, 16, 16, Box3(Vec3::Zero(), Vec3(1.0, 1.0, 1.0)));
  const ElementId last(grid.numElements() - 1);
  FaceId interior, boundary;
  for (const FaceUse& use : grid.element(ElementId(0)).faces)
    (grid.face(use.face).isBoundary() ? boundary : interior) = use.face;
  ASSERT_TRUE(interior.valid() && boundary.valid());
  auto withExtraUse = [&](FaceUse extra) {
    ElementData<Element> elements = grid.elements();
    elements[last].faces.push_back(extra);
    PolyMesh mesh;
    mesh.assign(grid.positions(), grid.faces(), std::move(elements));
    return mesh;
  };
  const auto message = [](const PolyMesh& mesh) {
    try {
      faceUses(mesh);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(withExtraUse({interior, true})),
            "face " + std::to_string(interior.value) + " is used by more than two elements");
  const bool firstWay = grid.face(boundary).front == ElementId(0) ? false : true;
  EXPECT_EQ(message(withExtraUse({boundary, firstWay})),
            "face " + std::to_string(boundary.value) + " is used twice with the same orientation");
  EXPECT_EQ(message(withExtraUse({boundary, !firstWay})), "no error");
}

TEST(FaceQuadrature, IntegratesMonomialsOverANonConvexFaceWithAHole) {
  Polygon2 h;
  h.outer = {{0, 0}, {3, 0}, {3, 1}, {1, 1}, {1, 3}, {0, 3}};  // an L
  h.holes = {{{0.25, 0.25}, {0.25, 0.75}, {0.75, 0.75}, {0.75, 0.25}}};
  const PolyMesh mesh = prismMesh(h, 0.0, 1.0);
  // The bottom face (z = 0) of the prism: find it by its normal.
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const FaceId id(f);
    if (std::abs(unitNormal(mesh, id).z()) < 0.5) continue;
    const int degree = 6;
    std::vector<double> exact(numMonomials(degree));
    Vec3 normal;
    faceMoments(mesh, id, degree, exact, normal);
    const Vec3& c = faceReferencePoint(mesh, id);
    const auto rule = faceQuadrature(mesh, id, degree);
    for (int a = 0; a < numMonomials(degree); ++a) {
      const Exponents e = monomialExponents(a);
      double s = 0.0;
      for (const QuadraturePoint& q : rule) {
        const Vec3 d = q.point - c;
        s += q.weight * std::pow(d.x(), e.a) * std::pow(d.y(), e.b) * std::pow(d.z(), e.c);
      }
      EXPECT_NEAR(s, exact[a], 1e-12 * std::max(1.0, std::abs(exact[a]))) << "monomial " << a;
    }
  }
}

}  // namespace
}  // namespace polydg
