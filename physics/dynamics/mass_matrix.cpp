#include "physics/dynamics/mass_matrix.h"

#include <tbb/parallel_for.h>

#include "physics/dg/local_integrators.h"

namespace polydg {

MassMatrix::MassMatrix(const DgBasis& basis, const MomentCache& moments, double density)
    : n_(basis.size()), ne_(basis.numElements()) {
  const int n = n_;
  mass_.assign(ne_ * n * n, 0.0);
  massOne_.assign(ne_ * n, 0.0);
  inverse_.assign(ne_, Eigen::LLT<Eigen::MatrixXd>());
  // The centre of mass keeps coordinates bounded for bodies far from the world's origin.
  Vec3 first = Vec3::Zero();
  double volume = 0.0;
  for (std::size_t i = 0; i < ne_; ++i) {
    volume += moments.volume(ElementId(i));
    first += moments.volume(ElementId(i)) * moments.centroid(ElementId(i));
  }
  centre_ = volume > 0.0 ? Vec3(first / volume) : Vec3::Zero();
  total_ = density * volume;
  tbb::parallel_for(std::size_t(0), ne_, [&](std::size_t i) {
    const ElementId e(i);
    Eigen::MatrixXd me;
    elementMass(basis, moments, e, me);
    me *= density;
    Eigen::Map<Eigen::MatrixXd>(mass_.data() + i * n * n, n, n) = me;
    inverse_[i].compute(me);
    const Eigen::VectorXd one = affineCoefficients(basis, e, 1.0, Vec3::Zero(), centre_);
    Eigen::Map<Eigen::VectorXd>(massOne_.data() + i * n, n) = me * one;
  });
}

void MassMatrix::times(const Eigen::VectorXd& x, Eigen::VectorXd& out) const {
  out.resize(x.size());
  const int n = n_, bs = 3 * n_;
  tbb::parallel_for(std::size_t(0), ne_, [&](std::size_t i) {
    const Eigen::Map<const Eigen::MatrixXd> me(mass_.data() + i * n * n, n, n);
    for (int d = 0; d < 3; ++d) {
      const Eigen::Index base = static_cast<Eigen::Index>(i * bs + d * n);
      out.segment(base, n).noalias() = me * x.segment(base, n);
    }
  });
}

Eigen::VectorXd MassMatrix::solve(const Eigen::VectorXd& b) const {
  Eigen::VectorXd x(b.size());
  const int n = n_, bs = 3 * n_;
  tbb::parallel_for(std::size_t(0), ne_, [&](std::size_t i) {
    for (int d = 0; d < 3; ++d) {
      const Eigen::Index base = static_cast<Eigen::Index>(i * bs + d * n);
      x.segment(base, n) = inverse_[i].solve(b.segment(base, n));
    }
  });
  return x;
}

}  // namespace polydg
