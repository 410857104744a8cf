// Groups of the blocks of a symmetric positive definite block matrix that are coupled more
// strongly than block Gauss-Seidel can smooth: the smoother blocks of the p-multigrid
// (physics/solvers/p_multigrid.h).
#pragma once

#include <span>
#include <vector>

namespace polydg {

template <class T>
struct BlockRows;

/// The strength of the coupling of blocks e and f of an SPD matrix A with diagonal blocks
/// D_e, D_f and off-diagonal block A_ef: gamma_ef = || D_e^-1/2 A_ef D_f^-1/2 ||_2, the
/// cosine of the angle between the subspaces of e's and f's unknowns in the A inner product
/// (the strengthened Cauchy-Schwarz constant). Dimensionless, in [0, 1) for SPD A, the same
/// under any scaling of A or change of basis within a block. Block Gauss-Seidel on the two
/// blocks alone contracts the error by gamma^2 per sweep: the mode in which e and f move
/// together costs 1 - gamma of what the blocks see.
/// The strengths of `a`'s stored slots, in slot order: strength[k] for slot k of row e
/// against element[k] (0 for the diagonal slots and for zero blocks). Symmetric
/// (gamma_ef = gamma_fe).
template <class T>
std::vector<double> couplingStrengths(const BlockRows<T>& a);

/// Blocks joined into groups: group g is blocks members[start[g] .. start[g + 1] - 1], in
/// increasing order; groups in the order of their smallest block.
struct BlockGroups {
  std::vector<int> start, members;

  int groups() const { return start.empty() ? 0 : static_cast<int>(start.size()) - 1; }
  int size(int g) const {
    return start[static_cast<std::size_t>(g) + 1] - start[static_cast<std::size_t>(g)];
  }
  /// Group g's blocks, in increasing order.
  std::span<const int> of(int g) const {
    return {members.data() + start[static_cast<std::size_t>(g)], static_cast<std::size_t>(size(g))};
  }
  /// Every group a single block.
  bool singletons() const { return members.size() + 1 == start.size(); }
};

/// The blocks of `a` joined along their strong couplings: pairs with gamma_ef >= `threshold`
/// (couplingStrengths()), strongest first, unless the union would exceed `maxBlocks` blocks.
/// A matrix with no strong coupling gives singletons.
template <class T>
BlockGroups groupStrongCouplings(const BlockRows<T>& a, double threshold, int maxBlocks);

/// The threshold the p-multigrid's smoother joins blocks at, for a discretization of degree
/// p (all its levels): gamma >= sqrt(3)/2 for p >= 2, where block Gauss-Seidel on the pair
/// alone would remove less than a quarter (1 - gamma^2) of its error per sweep, and gamma >=
/// 3/4 for p = 1 (less than 44%). Dimensionless. Both lie above every coupling of a hex grid
/// at that degree, whose block Gauss-Seidel smooths well, so hex grids keep one block per
/// element: B2's cube couples at most 0.64 at p = 1, and B1's at most 0.86 at p = 3. Why lower
/// for p = 1: clipped elements couple there from 3/4 up too, and joining them saves iterations
/// at about the same cost; a lower threshold makes larger groups and a slower smoother, and at
/// p = 2 the threshold of p = 1 would join most elements of a hex grid.
inline constexpr double kSmootherStrongCoupling = 0.86602540378443865;  // sqrt(3) / 2
inline constexpr double kLinearSmootherStrongCoupling = 0.75;
inline constexpr double smootherStrongCoupling(int degree) {
  return degree == 1 ? kLinearSmootherStrongCoupling : kSmootherStrongCoupling;
}

}  // namespace polydg
