#include "physics/solvers/strong_coupling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>

#include <tbb/parallel_for.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "physics/dg/block_rows.h"
#include "util/union_find.h"

namespace polydg {

namespace {

/// Power iteration for ||M||_2: at most this many steps, stopping once the estimate changes
/// by less than kPowerTolerance relative (it rises monotonically to the norm). The strengths
/// are compared with a threshold and ordered, so three digits are plenty.
constexpr int kPowerSteps = 100;
constexpr double kPowerTolerance = 1e-4;

/// ||m||_2 by power iteration on m^T m from a fixed start with no symmetry of the block.
template <class Mat>
double spectralNorm(const Mat& m) {
  using Vec = Eigen::Matrix<double, Mat::ColsAtCompileTime, 1>;
  Vec v = Vec::LinSpaced(m.cols(), 1.0, 2.0);
  v.normalize();
  Vec w(m.cols());
  double estimate = 0.0;
  for (int step = 0; step < kPowerSteps; ++step) {
    w.noalias() = m.transpose() * (m * v);
    const double norm = w.norm();
    if (!(norm > 0.0)) return 0.0;
    const double next = std::sqrt(norm);  // |M^T M v| with |v| = 1: at most sigma_max^2
    v = w / norm;
    if (std::abs(next - estimate) <= kPowerTolerance * next) return next;
    estimate = next;
  }
  return estimate;
}

/// couplingStrengths() with blocks of BS x BS (Eigen::Dynamic: a.bs, known at run time only):
/// fixed sizes keep the per-pair matrices on the stack. At p = 2 forming M (two triangular
/// solves per pair) costs the most either way. A pair whose ||M||_F, an upper bound of its
/// strength, is below `cutoff` gets that bound instead: no power iteration for a pair that
/// cannot reach a threshold of `cutoff` (most pairs of a time step's matrix, whose mass
/// weakens every coupling).
template <int BS, class T>
void strengthsOfSize(const BlockRows<T>& a, std::vector<double>& strength, double cutoff) {
  using Mat = Eigen::Matrix<double, BS, BS>;
  const int ne = a.elements(), bs = a.bs;
  const std::size_t bs2 = static_cast<std::size_t>(bs) * static_cast<std::size_t>(bs);
  // Each element's Cholesky factor L_e (D_e = L_e L_e^T), column-major; ok[e] = 0 if D_e is
  // not positive definite (no strength then).
  std::vector<double> factors(static_cast<std::size_t>(ne) * bs2);
  std::vector<std::uint8_t> ok(static_cast<std::size_t>(ne), 0);
  tbb::parallel_for(0, ne, [&](int e) {
    const T* values = a.diagonalBlock(e);
    Mat block(bs, bs);
    for (std::size_t i = 0; i < bs2; ++i) block.data()[i] = static_cast<double>(values[i]);
    const Eigen::LLT<Mat> llt(block);
    if (llt.info() != Eigen::Success) return;
    Eigen::Map<Mat>(factors.data() + static_cast<std::size_t>(e) * bs2, bs, bs) = llt.matrixL();
    ok[static_cast<std::size_t>(e)] = 1;
  });
  auto factor = [&](int e) {
    return Eigen::Map<const Mat>(factors.data() + static_cast<std::size_t>(e) * bs2, bs, bs);
  };
  // Each pair once, from its smaller element; then mirrored.
  tbb::parallel_for(0, ne, [&](int e) {
    if (!ok[static_cast<std::size_t>(e)]) return;
    Mat m(bs, bs);
    for (int k = a.start[static_cast<std::size_t>(e)]; k < a.start[static_cast<std::size_t>(e) + 1];
         ++k) {
      const std::size_t slot = static_cast<std::size_t>(k);
      const int f = a.element[slot];
      if (f <= e || !ok[static_cast<std::size_t>(f)]) continue;
      // M = L_e^-1 A_ef L_f^-T.
      m.setZero();
      a.copySlot(slot, m.data(), bs);
      factor(e).template triangularView<Eigen::Lower>().solveInPlace(m);
      factor(f).template triangularView<Eigen::Lower>().solveInPlace(
          m.transpose());  // (L_f^-1 M^T)^T = M L_f^-T
      const double bound = m.norm();
      strength[slot] = bound < cutoff ? bound : spectralNorm(m);
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
}

/// couplingStrengths(), exact from `cutoff` up (strengthsOfSize()).
template <class T>
std::vector<double> strengthsFrom(const BlockRows<T>& a, double cutoff) {
  std::vector<double> strength(a.element.size(), 0.0);
  switch (a.bs) {  // the block sizes of the DG degrees 0-3
    case 3: strengthsOfSize<3>(a, strength, cutoff); break;
    case 12: strengthsOfSize<12>(a, strength, cutoff); break;
    case 30: strengthsOfSize<30>(a, strength, cutoff); break;
    case 60: strengthsOfSize<60>(a, strength, cutoff); break;
    default: strengthsOfSize<Eigen::Dynamic>(a, strength, cutoff); break;
  }
  return strength;
}

}  // namespace

template <class T>
std::vector<double> couplingStrengths(const BlockRows<T>& a) {
  return strengthsFrom(a, 0.0);
}

template <class T>
BlockGroups groupStrongCouplings(const BlockRows<T>& a, double threshold, int maxBlocks) {
  const int ne = a.elements();
  // Exact where it matters: pairs below the threshold are not joined, whatever their strength.
  const std::vector<double> strength = strengthsFrom(a, threshold);
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
