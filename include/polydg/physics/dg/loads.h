// Boundary conditions and loads of a static elasticity problem: weak Dirichlet displacements
// and tractions on boundary faces chosen by a selector, and body forces.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include <string>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/plane.h"

namespace polydg {

/// A vector field of position, e.g. a prescribed displacement or a force density.
using VectorField = std::function<Vec3(const Vec3&)>;

/// Chooses boundary faces (faces used by one element only; interior faces are never chosen) by
/// where they lie: the one region selection of clamps and tractions, in `polydg solve`, pipeline
/// solve steps and simulation scenes. A face is chosen when all its vertices are in the region.
struct FaceSelector {
  enum class Kind {
    AllBoundary,  ///< every boundary face
    /// Faces lying in `plane`: every vertex within kPlaneSelectorTolerance times the mesh's
    /// bounding-box diagonal of it (a face of a scanned model is never exactly in a plane that
    /// was typed in; use Below or Box for those).
    Plane,
    /// Faces in the closed half-space normal . x <= offset of `plane`, decided exactly.
    Below,
    /// Faces in the closed axis-aligned `box`, decided exactly.
    Box,
  };
  Kind kind = Kind::AllBoundary;
  Plane plane;  ///< Plane, Below
  Box3 box;     ///< Box

  static FaceSelector allBoundary() { return {}; }
  /// The faces in the plane x_axis = value (axis 0, 1, 2 for x, y, z).
  static FaceSelector inPlane(int axis, double value) {
    return inPlane(Plane::axisAligned(axis, value));
  }
  static FaceSelector inPlane(const Plane& p) { return {Kind::Plane, p, Box3()}; }
  static FaceSelector below(const Plane& p) { return {Kind::Below, p, Box3()}; }
  /// Throws std::invalid_argument for a box with non-finite corners or min > max.
  static FaceSelector inBox(const Box3& b);

  /// The region in words and numbers, as users write it: "the plane z = 0", "the plane
  /// 1,0,1,0.5", "below 0,0,1,0.1", "the box [0,0,0]-[1,1,0.2]", "the whole boundary".
  std::string describe() const;
};

/// Relative tolerance of FaceSelector::Plane: a vertex lies in the plane when its distance
/// from it is at most this times the mesh's bounding-box diagonal.
inline constexpr double kPlaneSelectorTolerance = 1e-9;

/// True if boundary face f is selected; `meshDiagonal` is meshBounds(mesh).diagonal().norm().
bool selects(const FaceSelector& selector, const PolyMesh& mesh, FaceId f, double meshDiagonal);

/// u = g on the selected faces, imposed weakly (Nitsche: the same face terms as interior
/// faces with the outside value g). `g` is integrated by face quadrature.
struct DirichletCondition {
  FaceSelector where;
  VectorField displacement;  ///< g(x); empty for g = 0 (a clamp)
};

/// A constant traction t (force per area) on the selected faces, integrated exactly (a face
/// rule of the basis degree).
struct TractionCondition {
  FaceSelector where;
  Vec3 traction = Vec3::Zero();
};

/// Everything applied to the body. A face chosen by a Dirichlet condition is not loaded by a
/// traction; of several Dirichlet conditions choosing a face, the first applies.
struct LoadCase {
  std::vector<DirichletCondition> dirichlet;
  std::vector<TractionCondition> tractions;
  /// Gravitational acceleration; the body force is density * gravity (exact, from moments).
  Vec3 gravity = Vec3::Zero();
  /// An additional body force per volume, integrated by quadrature on the signed cone
  /// decomposition of each element (integrate/quadrature.h); empty for none.
  VectorField bodyForce;
};

}  // namespace polydg
