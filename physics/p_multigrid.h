// A p-multigrid preconditioner for the DG stiffness matrices: a symmetric V-cycle over the
// polynomial degrees p, p-1, ..., 0 of the same mesh, smoothed by multicolour block
// Gauss-Seidel over the elements, with the piecewise constant level factorized by CHOLMOD.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/SparseCore>

namespace polydg {

template <class T>
struct BlockRows;

/// The V-cycle as an SPD preconditioner for conjugate gradients.
///
/// Levels. The DG bases are hierarchical (DgBasis: functions 0 .. numMonomials(q)-1 of each
/// element span the polynomials of degree <= q), so the Galerkin coarse matrix P^T K P of
/// degree q < p, with P the embedding of degree-q functions, is the principal submatrix of K
/// on those DOFs: no interpolation operators are formed and restriction/prolongation are
/// index maps. Level 0 holds the per-element constants (3 unknowns per element).
///
/// Smoother. Block Gauss-Seidel with one block per element (exact inverse of the element's
/// diagonal block), elements visited colour by colour (a greedy colouring of the element graph
/// of K, so that elements of one colour share no block and are updated in parallel):
/// colours in order before the coarse correction and in reverse order after it, which makes
/// the V-cycle a symmetric positive definite operator (a valid CG preconditioner) whenever K
/// is SPD.
///
/// Not thread-safe: apply() uses scratch vectors of the object.
class PMultigrid {
 public:
  PMultigrid();
  ~PMultigrid();
  PMultigrid(PMultigrid&&) noexcept;
  PMultigrid& operator=(PMultigrid&&) noexcept;

  /// Builds the levels of `matrix` (symmetric, both triangles stored, element e's DOFs the
  /// range [e bs, (e + 1) bs) in the order d n + i, bs = 3 n, n = numMonomials(degree) as in
  /// LinearSystem). `matrix` must stay alive while the preconditioner is used. Returns false
  /// if a diagonal block or the level-0 matrix is found not positive definite. A body held by
  /// no Dirichlet condition makes level 0 exactly singular, which the factorization may miss
  /// on rounding: CG then fails to converge and reports it (SolveReport::success).
  /// `matrixBlocks`, if given with values, is `matrix` by block rows (BlockRows): the top
  /// level's smoother copy is then converted from it instead of built from the CSR matrix.
  bool compute(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix, int degree,
               const BlockRows<double>* matrixBlocks = nullptr);

  /// z = M^-1 r: one V-cycle for K z = r from z = 0.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;

  /// Number of levels (degree + 1) and colours of the element graph.
  int levels() const;
  int colours() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace polydg
