#include "physics/dg/reactions.h"

#include "physics/dg/face_quadrature.h"
#include "polydg/physics/dg/post_process.h"

namespace polydg {

std::vector<Vec3> dirichletForces(const PolyMesh& mesh, const DgBasis& basis,
                                  const MomentCache& moments, const FaceRoles& roles,
                                  const Material& material, const Eigen::VectorXd& coefficients,
                                  std::size_t conditions) {
  std::vector<Vec3> out(conditions, Vec3::Zero());
  const double mu = material.mu(), lambda = material.lambda();
  // Face order, one sum per condition: the result does not depend on threads.
  for (std::size_t i = 0; i < mesh.numFaces(); ++i) {
    const FaceId f(i);
    if (roles.kind[f] != FaceKind::Dirichlet) continue;
    const FaceUses& uses = roles.uses[f];
    const ElementId k = uses.element[0];
    const Vec3 n = uses.reversed[0] ? Vec3(-moments.faceNormal(f)) : moments.faceNormal(f);
    Vec3 force = Vec3::Zero();
    for (const QuadraturePoint& q : faceQuadrature(mesh, f, 2 * basis.degree())) {
      const Eigen::Matrix3d g = displacementGradientAt(basis, coefficients, k, q.point);
      const Eigen::Matrix3d eps = 0.5 * (g + g.transpose());
      const Eigen::Matrix3d sigma =
          2.0 * mu * eps + lambda * eps.trace() * Eigen::Matrix3d::Identity();
      force += q.weight * (sigma * n);
    }
    out[static_cast<std::size_t>(roles.dirichlet[f])] += force;
  }
  return out;
}

}  // namespace polydg
