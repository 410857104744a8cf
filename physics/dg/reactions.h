// The forces a solution's stress puts on its Dirichlet boundaries (the clamps' reactions).
#pragma once

#include <vector>

#include "physics/dg/assembly.h"
#include "polydg/physics/dg/dg_basis.h"
#include "polydg/physics/dg/material.h"

namespace polydg {

/// For each of `conditions` Dirichlet conditions (LoadCase::dirichlet's order), the force the
/// body's stress exerts on its faces, int_F sigma(u_h) n dA with n out of the body, by face
/// quadrature of degree 2p. At equilibrium it balances the applied loads up to the error of the
/// discrete stress (exactly when the solution is exact, as for a linear one). The penalty terms
/// of the weak condition are not included: this is the physical traction, independent of K.
std::vector<Vec3> dirichletForces(const PolyMesh& mesh, const DgBasis& basis,
                                  const MomentCache& moments, const FaceRoles& roles,
                                  const Material& material, const Eigen::VectorXd& coefficients,
                                  std::size_t conditions);

}  // namespace polydg
