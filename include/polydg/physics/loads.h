// Boundary conditions and loads of a static elasticity problem: weak Dirichlet displacements
// and tractions on boundary faces chosen by a selector, and body forces.
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "polydg/mesh/geometry.h"

namespace polydg {

/// A vector field of position, e.g. a prescribed displacement or a force density.
using VectorField = std::function<Vec3(const Vec3&)>;

/// Chooses boundary faces (faces used by one element only; interior faces are never chosen).
struct FaceSelector {
  enum class Kind {
    AllBoundary,  ///< every boundary face
    Plane,        ///< boundary faces whose vertices all lie in the plane x_axis = value
  };
  Kind kind = Kind::AllBoundary;
  int axis = 0;        ///< 0, 1, 2 for x, y, z (Plane only)
  double value = 0.0;  ///< the plane's coordinate (Plane only)

  static FaceSelector allBoundary() { return {}; }
  static FaceSelector plane(int axis, double value) { return {Kind::Plane, axis, value}; }
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
