// The consistent mass matrix of a DG basis, from the exact moments: one n x n block per
// element (the same for each displacement component), its inverse, and the body's mass and
// undeformed centre of mass.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "polydg/physics/dg/dg_basis.h"

namespace polydg {

class MassMatrix {
 public:
  /// rho int phi_i phi_j over every element of `basis` (its mesh's `moments`, degree >= 2p).
  MassMatrix(const DgBasis& basis, const MomentCache& moments, double density);

  /// out = M x (LinearSystem's layout).
  void times(const Eigen::VectorXd& x, Eigen::VectorXd& out) const;
  /// M^-1 b, element block by element block.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  /// Element blocks, n x n each, column-major, one after the other.
  const std::vector<double>& blocks() const { return mass_; }
  /// rho int_K phi_i of element i, n values: the momentum of a velocity is their dot product
  /// with each component's coefficients.
  Eigen::Map<const Eigen::VectorXd> integrals(std::size_t i) const {
    return {massOne_.data() + i * n_, n_};
  }
  double total() const { return total_; }
  /// The undeformed body's centre of mass.
  const Vec3& centre() const { return centre_; }

 private:
  int n_ = 0;
  std::size_t ne_ = 0;
  std::vector<double> mass_;
  std::vector<double> massOne_;
  std::vector<Eigen::LLT<Eigen::MatrixXd>> inverse_;
  double total_ = 0.0;
  Vec3 centre_ = Vec3::Zero();
};

}  // namespace polydg
