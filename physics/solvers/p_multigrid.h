// A multigrid preconditioner for the DG stiffness matrices: a symmetric V-cycle over the
// polynomial degrees p, p-1, ..., min(p, 2) of the same mesh and then, given the elements'
// frames, over the polynomials of that degree on agglomerates of elements (groups of about
// 2 x 2 x 2), smoothed by multicolour block Gauss-Seidel over elements (strongly coupled ones in
// groups), with the coarsest level factorized by CHOLMOD. Without frames the coarsest level is
// the piecewise constants (degree 0) of the mesh.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace polydg {

template <class T>
struct BlockRows;
struct ElementFrames;

/// What the matrices a p-multigrid is built for hold.
enum class MatrixTerms {
  Stiffness,  ///< K alone: a static solve
  /// A time step's cM M + cK K. The mass term holds the modes the coarse levels correct, so
  /// their smoothing matters less: the aggregation levels sweep once, not twice (B10's beam:
  /// 11.11 -> 11.33 V-cycles a step, a fifth cheaper each; K alone would take a tenth more).
  StiffnessAndMass,
};

/// The V-cycle as an SPD preconditioner for conjugate gradients.
///
/// Degree levels. The DG bases are hierarchical (DgBasis: functions 0 .. numMonomials(q)-1 of
/// each element span the polynomials of degree <= q), so the Galerkin coarse matrix P^T K P of
/// degree q < p, with P the embedding of degree-q functions, is the principal submatrix of K
/// on those DOFs: no interpolation operators are formed and restriction/prolongation are
/// index maps.
///
/// Agglomeration levels. Below degree 1, piecewise constants are a poor coarse space for
/// elasticity: they cannot represent rotations, which cost nothing in K but much in the
/// penalty between constants. Instead, elements are grouped into agglomerates (the elements of
/// 2 x 2 x 2 cells of the lattice the mesh was sliced on, split into face-coupled components;
/// without a lattice, three rounds of pairing face neighbours, each round along one axis:
/// physics/solvers/agglomeration.h) and the coarse space is the polynomial displacements of each
/// agglomerate, rigid motions included: linear for p = 1 (12 unknowns per agglomerate),
/// quadratic for p >= 2 (30), reached straight from degree 2 (P built from the frames; the
/// Galerkin matrix P^T K P is formed block by block). Agglomerates are grouped again, with
/// quadratic functions (for p = 1 too: each linear agglomerate takes the Taylor part of its
/// group's quadratics; combinations its blocks cannot tell apart, as on a line of agglomerates,
/// are dropped, Agglomeration::spans), until the coarsest level has few unknowns. Why
/// quadratic: a thin part, one element thick, bends at little cost in K, but linear
/// displacements per agglomerate bend it only through jumps between agglomerates, which pay the
/// penalty; quadratic ones bend it inside each. For p = 1 the first agglomeration level stays
/// linear: quadratic agglomerates of linear elements save iterations, but their level has as
/// many nonzeros as K, which makes the V-cycle slower.
///
/// Smoother. Block Gauss-Seidel with one block per element or agglomerate, except where blocks
/// are strongly coupled: blocks whose coupling strength gamma (the cosine of the angle between
/// their unknowns in the energy inner product, physics/solvers/strong_coupling.h) is at least
/// sqrt(3)/2 (3/4 for p = 1) are solved together, in groups of up to 16 (union-find, strongest
/// pairs first), each with the exact inverse of its diagonal block. Such pairs are found across
/// faces of elements clipped by the surface; on hex grids none reaches the threshold and every
/// group is one block. Groups are visited colour by colour (a greedy colouring of the level's group
/// graph, so that groups of one colour share no entry and are updated in parallel): colours in
/// order before the coarse correction and in reverse order after it, which makes the V-cycle a
/// symmetric positive definite operator (a valid CG preconditioner) whenever K is SPD. Groups
/// save iterations on clipped meshes and leave hex grids as they are.
///
/// Not thread-safe: apply() uses scratch vectors of the object.
class PMultigrid {
 public:
  explicit PMultigrid(MatrixTerms terms = MatrixTerms::Stiffness);
  ~PMultigrid();
  PMultigrid(PMultigrid&&) noexcept;
  PMultigrid& operator=(PMultigrid&&) noexcept;

  /// Builds the levels of `matrix` (symmetric, both triangles stored, element e's DOFs the
  /// range [e bs, (e + 1) bs) in the order d n + i, bs = 3 n, n = numMonomials(degree) as in
  /// LinearSystem). `matrix` must stay alive while the preconditioner is used. Returns false
  /// if a diagonal block or the level-0 matrix is found not positive definite. A body held by
  /// no Dirichlet condition makes level 0 exactly singular, which the factorization may miss
  /// on rounding: CG then fails to converge and reports it (LinearSolveReport::success).
  /// `matrixBlocks`, if given with values, is `matrix` by block rows (BlockRows): the top
  /// level's smoother copy is then converted from it instead of built from the CSR matrix.
  /// `frames`, if given (one per element), replace the degree-0 level by agglomeration levels.
  bool compute(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix, int degree,
               const BlockRows<double>* matrixBlocks = nullptr,
               const ElementFrames* frames = nullptr);

  /// The same from K by block rows alone (double precision, e.g. assembleBlockRows()), which
  /// must stay alive while the preconditioner is used: the top level's smoother reads them as
  /// they are (no CSR matrix and no single-precision copy), the lower degree levels are their
  /// principal submatrices. The one copy of K a CG solve then keeps.
  bool compute(const BlockRows<double>& rows, int degree, const ElementFrames* frames = nullptr);

  /// The same from K by block rows that the caller rewrites between applications (a time
  /// step's matrix): the levels are built from them, and the smoother keeps its own copy in
  /// single precision, so the V-cycle stays the one of the matrix it was built for (symmetric
  /// positive definite) while the rows change. `rows` is read during the call only.
  bool computeCopy(const BlockRows<double>& rows, int degree,
                   const ElementFrames* frames = nullptr);

  /// z = M^-1 r: one V-cycle for K z = r from z = 0.
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;

  /// Number of levels (degree + 1 without frames) and colours of the top level's smoother
  /// groups.
  int levels() const;
  int colours() const;
  /// Blocks (elements) of the top level that the smoother solves in groups of more than one.
  int groupedBlocks() const;
  /// Unknowns of the coarsest level (the one factorized).
  Eigen::Index coarseUnknowns() const;
  /// Gauss-Seidel sweeps of level k's smoother before (and after) its coarse correction; 0 for
  /// the coarsest level (factorized).
  int sweeps(int level) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace polydg
