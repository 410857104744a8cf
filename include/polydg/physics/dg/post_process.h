// Quantities derived from a DG solution: point values and gradients, the corner values that
// eq. (17) averages at the vertices, per-element mean displacement, von Mises stress and largest
// jump, and error norms against a known solution.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "polydg/mesh/vtu_io.h"
#include "polydg/physics/dg/dg_basis.h"
#include "polydg/physics/dg/material.h"

namespace polydg {

/// u_h(x) restricted to element e (x may lie outside e: the element's polynomial is used).
Vec3 displacementAt(const DgBasis& basis, const Eigen::VectorXd& coefficients, ElementId e,
                    const Vec3& x);

/// The displacement gradient G(d, k) = d u_d / d x_k of element e's polynomial at x.
Eigen::Matrix3d displacementGradientAt(const DgBasis& basis, const Eigen::VectorXd& coefficients,
                                       ElementId e, const Vec3& x);

/// u|_K(v) at every corner (element K, vertex v of K): the values that paper eq. (17) averages
/// at each vertex. Element e's distinct face vertices are vertices[begin[e] .. begin[e + 1]),
/// in increasing order, with their values alongside.
struct CornerValues {
  std::vector<std::size_t> begin;
  std::vector<VertexId> vertices;
  std::vector<Vec3> values;

  /// u|_e(v); throws std::logic_error if v is not a vertex of e.
  const Vec3& at(ElementId e, VertexId v) const;
  /// The largest |u|_K(v)| over all corners (0 without elements).
  double largestNorm() const;
};

CornerValues cornerDisplacements(const PolyMesh& mesh, const DgBasis& basis,
                                 const Eigen::VectorXd& coefficients);

/// Paper eq. (17) as VTU point data named `name`: each point written for a vertex holds the
/// mean of u|_K(vertex) over the elements K it stands for, so the two sides of a cut keep
/// their own means (mesh/vtu_io.h, CornerArray). `corners` must outlive the write.
CornerArray displacementPointData(const CornerValues& corners, std::string name = "displacement");

/// The same from `coefficients` on `basis` directly: each corner's u|_K(v) is evaluated when
/// the writer asks for it (displacementAt(), the value cornerDisplacements() stores), with no
/// table of corners made first. For the frames of a time series: on the bunny sliced at 40
/// cells the table took half of a frame (58 of 115 ms), most of it finding each element's
/// vertices again. `mesh`, `basis` and `coefficients` must outlive the write.
CornerArray displacementPointData(const PolyMesh& mesh, const DgBasis& basis,
                                  const Eigen::VectorXd& coefficients,
                                  std::string name = "displacement");

struct ElementFields {
  ElementData<Vec3> meanDisplacement;  ///< (1/vol) int_K u_h
  ElementData<double> vonMises;        ///< von Mises stress of the element's mean stress
  /// The mean stress's eigenvalue of largest absolute value (signed) and its unit eigenvector:
  /// the stress refinement measures (paper section 10).
  ElementData<double> principalStress;
  ElementData<Vec3> principalDirection;
  ElementData<double> largestJump;  ///< max |u_K - u_L| at the vertices of interior faces
};

/// Per-element fields of a solution (moments up to degree p, e.g. the solve's cache).
ElementFields elementFields(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                            const Eigen::VectorXd& coefficients, const Material& material);

/// Gradient of a vector field: G(d, k) = d u_d / d x_k.
using GradientField = std::function<Eigen::Matrix3d(const Vec3&)>;

struct ErrorNorms {
  double l2 = 0.0;       ///< |u - u_h|_L2
  double h1 = 0.0;       ///< broken H1 seminorm: sqrt(sum_K |grad(u - u_h)|^2_L2(K))
  double l2Exact = 0.0;  ///< |u|_L2
  double h1Exact = 0.0;  ///< |grad u|_L2
};

/// Errors against (u, grad u) by element quadrature (integrate/quadrature.h) exact to
/// `quadratureDegree` (use >= p + 4 for smooth u).
ErrorNorms errorNorms(const PolyMesh& mesh, const DgBasis& basis,
                      const Eigen::VectorXd& coefficients,
                      const std::function<Vec3(const Vec3&)>& exact,
                      const GradientField& exactGradient, int quadratureDegree);

/// Coefficients of the element-wise L2 projection of `field` onto the basis (quadrature of
/// degree `quadratureDegree`; exact for polynomial fields of degree <= quadratureDegree - p).
Eigen::VectorXd projectField(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                             const std::function<Vec3(const Vec3&)>& field, int quadratureDegree);

}  // namespace polydg
