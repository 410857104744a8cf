// One level of the p-multigrid V-cycle (physics/solvers/p_multigrid.h): its matrix in the forms
// the smoother reads, its smoother's groups with the inverses of their diagonal blocks, its
// colouring and its transfer to the next coarser level; and the block residual that the
// smoother and the restriction share.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "physics/dg/block_rows.h"
#include "physics/solvers/agglomeration.h"
#include "physics/solvers/strong_coupling.h"

namespace polydg::multigrid {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Largest element block handled (3 numMonomials(3)).
constexpr int kMaxBlock = 60;

/// How a level's unknowns reach the next coarser level.
enum class Transfer {
  Degree,     ///< the first numMonomials(q) functions of each element (index maps)
  Aggregate,  ///< polynomials of groups of blocks (weights per block)
};

/// One level: its matrix (the top level borrows K), functions per component, its smoother's
/// groups of blocks with the inverses of their diagonal blocks, its colouring and its
/// transfer to the next coarser level.
struct Level {
  const SpMat* matrix = nullptr;
  SpMat owned;
  /// The top level given by block rows alone (the caller's, double precision; no CSR matrix):
  /// the smoother reads them as they are.
  const BlockRows<double>* rows = nullptr;
  int n = 0, bs = 0;
  /// The smoother's blocks: groups of the level's blocks (elements or agglomerates) joined
  /// along strong couplings (groupStrongCouplings()), most of them single blocks. Group g's
  /// diagonal block inverted, (m bs) x (m bs) for its m blocks, column-major, at
  /// inverses[inverseOffset[g]].
  BlockGroups smootherGroups;
  std::vector<std::size_t> inverseOffset;
  std::vector<double> inverses;
  /// The smoother's copy of the matrix in single precision (BlockRows): half the bytes of
  /// the CSR values (a sixth for BZ's component-diagonal neighbour blocks) and no index per
  /// entry, for a smoother bound by memory bandwidth. Symmetric like the matrix, so the
  /// V-cycle stays symmetric (it is the V-cycle of the rounded matrix). Used when it stores
  /// at most twice the matrix's nonzeros; otherwise the smoother reads the CSR matrix.
  bool useBlocks = false;
  BlockRows<float> blocks;
  /// The matrix by block rows in double precision, for a level that is agglomerated: the
  /// grouping reads its block graph and the Galerkin product its values (the top level's copy
  /// is the caller's, `source`). An agglomeration level's Galerkin matrix is formed this way,
  /// with no CSR matrix unless it is the coarsest.
  BlockRows<double> exact;
  const BlockRows<double>* source = nullptr;
  /// Smoother groups of each colour, in increasing order (groups of one colour share no
  /// entry); inLastColour[b] = 1 for the blocks of the last colour's groups.
  std::vector<std::vector<int>> colours;
  std::vector<std::uint8_t> inLastColour;
  /// Gauss-Seidel sweeps before (and, reversed, after) the coarse correction.
  int sweeps = 1;
  Transfer transfer = Transfer::Degree;
  /// Aggregate transfer: the groups of this level's blocks that are the next level's blocks.
  Agglomeration groups;
  // Scratch of apply(): right-hand side and solution of this level.
  mutable Eigen::VectorXd b, x;

  /// Blocks (elements or groups) of the level, and its unknowns.
  Eigen::Index blockCount() const {
    return rows                   ? rows->elements()
           : useBlocks            ? blocks.elements()
           : !exact.start.empty() ? exact.elements()
                                  : matrix->cols() / bs;
  }
  Eigen::Index unknowns() const { return blockCount() * bs; }
};

/// s = b_e - (A x)_e for element e's rows, from the block rows of `level`.
inline void blockResidual(const Level& level, int e, const Eigen::VectorXd& b,
                          const Eigen::VectorXd& x, double* s) {
  const int bs = level.bs;
  const Eigen::Index base = static_cast<Eigen::Index>(e) * bs;
  if (level.rows) {
    for (int c = 0; c < bs; ++c) s[c] = b[base + c];
    level.rows->subtractRowProduct(e, x.data(), s);
    return;
  }
  if (!level.useBlocks) {
    const SpMat& a = *level.matrix;
    const int* outer = a.outerIndexPtr();
    const int* inner = a.innerIndexPtr();
    const double* values = a.valuePtr();
    // Column base + c of A is row base + c (symmetric storage).
    for (int c = 0; c < bs; ++c) {
      double sum = 0.0;
      for (int k = outer[base + c]; k < outer[base + c + 1]; ++k) sum += values[k] * x[inner[k]];
      s[c] = b[base + c] - sum;
    }
    return;
  }
  for (int c = 0; c < bs; ++c) s[c] = b[base + c];
  level.blocks.subtractRowProduct(e, x.data(), s);
}

}  // namespace polydg::multigrid
