#include "polydg/physics/strong_coupling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>

#include <tbb/parallel_for.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "polydg/physics/block_rows.h"
#include "polydg/util/union_find.h"

namespace polydg {

namespace {

/// Power iteration for ||M||_2: at most this many steps, stopping once the estimate changes
/// by less than kPowerTolerance relative (it rises monotonically to the norm). The strengths
/// are compared with a threshold and ordered, so three digits are plenty.
constexpr int kPowerSteps = 100;
constexpr double kPowerTolerance = 1e-4;

/// ||m||_2 by power iteration on m^T m from a fixed start with no symmetry of the block.
double spectralNorm(const Eigen::MatrixXd& m) {
  const Eigen::Index n = m.cols();
  Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0);
  v.normalize();
  double estimate = 0.0;
  for (int step = 0; step < kPowerSteps; ++step) {
    const Eigen::VectorXd w = m.transpose() * (m * v);
    const double norm = w.norm();
    if (!(norm > 0.0)) return 0.0;
    const double next = std::sqrt(norm);  // |M^T M v| with |v| = 1: at most sigma_max^2
    v = w / norm;
    if (std::abs(next - estimate) <= kPowerTolerance * next) return next;
    estimate = next;
  }
  return estimate;
}

/// A full copy of a stored slot: bs x bs, column-major, component-diagonal slots expanded.
template <class T>
Eigen::MatrixXd denseSlot(const BlockRows<T>& a, std::size_t slot) {
  Eigen::MatrixXd block = Eigen::MatrixXd::Zero(a.bs, a.bs);
  a.copySlot(slot, block.data(), a.bs);
  return block;
}

/// The Cholesky factor of e's diagonal block.
template <class T>
Eigen::LLT<Eigen::MatrixXd> diagonalFactor(const BlockRows<T>& a, int e) {
  const T* values = a.diagonalBlock(e);
  return Eigen::LLT<Eigen::MatrixXd>(
      Eigen::Map<const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>>(values, a.bs, a.bs)
          .template cast<double>());
}

}  // namespace

template <class T>
std::vector<double> couplingStrengths(const BlockRows<T>& a) {
  const int ne = a.elements();
  std::vector<double> strength(a.element.size(), 0.0);
  // Each pair once, from its smaller element; then mirrored.
  tbb::parallel_for(0, ne, [&](int e) {
    const int first = a.start[static_cast<std::size_t>(e)];
    const int last = a.start[static_cast<std::size_t>(e) + 1];
    bool any = false;
    for (int k = first; k < last && !any; ++k) any = a.element[static_cast<std::size_t>(k)] > e;
    if (!any) return;
    const Eigen::LLT<Eigen::MatrixXd> de = diagonalFactor(a, e);
    if (de.info() != Eigen::Success) return;
    for (int k = first; k < last; ++k) {
      const std::size_t slot = static_cast<std::size_t>(k);
      const int f = a.element[slot];
      if (f <= e) continue;
      const Eigen::LLT<Eigen::MatrixXd> df = diagonalFactor(a, f);
      if (df.info() != Eigen::Success) continue;
      // M = L_e^-1 A_ef L_f^-T.
      Eigen::MatrixXd m = de.matrixL().solve(denseSlot(a, slot));
      m = df.matrixL().solve(m.transpose()).transpose();
      strength[slot] = spectralNorm(m);
    }
  });
  tbb::parallel_for(0, ne, [&](int f) {
    for (int k = a.start[static_cast<std::size_t>(f)]; k < a.start[static_cast<std::size_t>(f) + 1];
         ++k) {
      const int e = a.element[static_cast<std::size_t>(k)];
      if (e >= f) continue;
      for (int t = a.start[static_cast<std::size_t>(e)];
           t < a.start[static_cast<std::size_t>(e) + 1]; ++t)
        if (a.element[static_cast<std::size_t>(t)] == f)
          strength[static_cast<std::size_t>(k)] = strength[static_cast<std::size_t>(t)];
    }
  });
  return strength;
}

template <class T>
BlockGroups groupStrongCouplings(const BlockRows<T>& a, double threshold, int maxBlocks) {
  const int ne = a.elements();
  const std::vector<double> strength = couplingStrengths(a);
  // Strong pairs (e < f), strongest first; ties in element order, so the groups do not
  // depend on the threads.
  std::vector<std::tuple<double, int, int>> pairs;
  for (int e = 0; e < ne; ++e)
    for (int k = a.start[static_cast<std::size_t>(e)]; k < a.start[static_cast<std::size_t>(e) + 1];
         ++k) {
      const int f = a.element[static_cast<std::size_t>(k)];
      if (f > e && strength[static_cast<std::size_t>(k)] >= threshold)
        pairs.emplace_back(-strength[static_cast<std::size_t>(k)], e, f);
    }
  std::sort(pairs.begin(), pairs.end());
  UnionFind sets(static_cast<std::size_t>(ne));
  std::vector<int> size(static_cast<std::size_t>(ne), 1);  // valid at the roots
  for (const auto& [minus, e, f] : pairs) {
    const std::uint32_t re = sets.find(static_cast<std::uint32_t>(e));
    const std::uint32_t rf = sets.find(static_cast<std::uint32_t>(f));
    if (re == rf || size[re] + size[rf] > maxBlocks) continue;
    sets.unite(re, rf);  // rf represents the union
    size[rf] += size[re];
  }
  std::vector<std::uint32_t> label;
  const std::size_t count = sets.labels(label);
  BlockGroups groups;
  groups.start.assign(count + 1, 0);
  for (std::uint32_t g : label) ++groups.start[g + 1];
  for (std::size_t g = 0; g < count; ++g) groups.start[g + 1] += groups.start[g];
  groups.members.resize(static_cast<std::size_t>(ne));
  std::vector<int> next(groups.start.begin(), groups.start.end() - 1);
  for (int e = 0; e < ne; ++e)  // in increasing order within each group
    groups.members[static_cast<std::size_t>(next[label[static_cast<std::size_t>(e)]]++)] = e;
  return groups;
}

template std::vector<double> couplingStrengths(const BlockRows<float>&);
template std::vector<double> couplingStrengths(const BlockRows<double>&);
template BlockGroups groupStrongCouplings(const BlockRows<float>&, double, int);
template BlockGroups groupStrongCouplings(const BlockRows<double>&, double, int);

}  // namespace polydg
