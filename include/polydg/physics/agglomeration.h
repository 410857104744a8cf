// Agglomeration of DG elements into groups of neighbours, and the linear displacements of each
// group as a coarse space: the coarse levels of the p-multigrid (physics/p_multigrid.h).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace polydg {

template <class T>
struct BlockRows;
class DgBasis;

/// What agglomeration needs of each element e: its basis's centre c_e and length scale h_e,
/// and how its first four scalar functions (degree <= 1) combine the scaled monomials
/// 1, (x - c_e) / h_e, (y - c_e) / h_e, (z - c_e) / h_e: phi_i = sum_a T_e(i, a) m_a (the
/// top-left 4 x 4 block of DgBasis::coefficients).
struct ElementFrames {
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> scales;
  std::vector<Eigen::Matrix4d> linear;
};

/// The frames of `basis`'s elements.
ElementFrames elementFrames(const DgBasis& basis);

/// Blocks (elements, or groups of a finer agglomeration) grouped, and the linear
/// displacements of each group expressed in its blocks' functions.
struct Agglomeration {
  /// Block b belongs to group parent[b]; group g's blocks are
  /// children[childStart[g] .. childStart[g + 1] - 1], in increasing order.
  std::vector<int> parent, childStart, children;
  /// Group g's linear functions M_j: 1, (x - C_g) / H_g, (y - C_g) / H_g, (z - C_g) / H_g. On
  /// its block b, M_j = sum_i W_b(i, j) phi_i over the block's first four functions, W_b
  /// column-major at weights[16 b]; the same for each displacement component.
  std::vector<double> weights;
  /// Each group's centre C_g (the mean of its blocks' centres) and scale H_g, large enough
  /// that |x - C_g| <= H_g on each block (given |x - c_b| <= h_b there).
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> scales;

  int groups() const { return static_cast<int>(centres.size()); }
};

/// Groups the blocks of a symmetric block matrix, given by block rows (neighbours: blocks that
/// share a stored block), by three rounds of greedy pairing: blocks, then pairs, then pairs of
/// pairs, round k pairing each group with its unpaired neighbour best aligned with axis k (the
/// line between their centres at most 60 degrees from the axis; groups in order). On a hex
/// grid this gives 2 x 2 x 2 blocks; on a sliced mesh, groups of up to 8 face neighbours.
/// `centres` and `scales` are the blocks' frames; `linear` their T (ElementFrames::linear), or
/// nullptr when the blocks' functions are the scaled monomials themselves (groups of a finer
/// agglomeration).
Agglomeration agglomerate(const BlockRows<double>& rows,
                          const std::vector<Eigen::Vector3d>& centres,
                          const std::vector<double>& scales,
                          const std::vector<Eigen::Matrix4d>* linear);

/// The Galerkin matrix P^T A P of the coarse space of `groups` (4 linear functions per
/// component of each group, unknown (g, d, j) at 12 g + 4 d + j), from A by block rows in
/// double precision (n = 4 functions per component). A coarse block whose displacement
/// components are uncoupled (BZ's) stores only its three diagonal 4 x 4 parts. Exactly
/// symmetric, both triangles stored.
Eigen::SparseMatrix<double, Eigen::ColMajor, int> galerkinMatrix(const Agglomeration& groups,
                                                                 const BlockRows<double>& rows);

}  // namespace polydg
