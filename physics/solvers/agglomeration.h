// Agglomeration of DG elements into groups of neighbours, and the linear or quadratic
// displacements of each group as a coarse space: the coarse levels of the p-multigrid
// (physics/solvers/p_multigrid.h).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>

namespace polydg {

template <class T>
struct BlockRows;
class DgBasis;
class PolyMesh;

/// What agglomeration needs of each element e: its basis's centre c_e and length scale h_e,
/// and how its first scalar functions, those of degree <= min(p, 2), combine the scaled
/// monomials m_a = ((x - c_e) / h_e)^a (order of integrate/monomials.h): phi_i = sum_a
/// T_e(i, a) m_a, `bases[e]` the top-left 4 x 4 (p = 1) or 10 x 10 block of
/// DgBasis::coefficients; and, if the mesh lies on a lattice of cells (latticeCells()), the
/// cell of each element, else `cells` is empty.
struct ElementFrames {
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> scales;
  std::vector<Eigen::MatrixXd> bases;
  std::vector<Eigen::Vector3i> cells;
};

/// The frames of `basis`'s elements on `mesh` (the mesh the basis was built on), with the
/// cells of latticeCells() of their bounding boxes.
ElementFrames elementFrames(const DgBasis& basis, const PolyMesh& mesh);

/// The cells of the lattice the elements were made on, inferred from their bounding boxes
/// `boxes` (one per element): cell (i, j, k) of element e holds its box centre,
/// origin + h * (i, j, k) <= centre < origin + h * (i + 1, j + 1, k + 1), indices >= 0.
/// Why inferred and not recorded: a sliced element is its grid cell clipped by the surface,
/// and cuts and refinement only make pieces inside it (a sliver merged across a cell face
/// joins two), so the lattice is in the geometry of every mesh made by slicing, by a hex grid
/// or read back from a VTU file, with no field to carry through each edit and file. Along each
/// axis the cell length h is the most common bounding-box extent (within 1e-6 h: a whole cell,
/// which most elements of a sliced mesh are) and the origin the lattice plane, at a multiple
/// of h from the lower side of an element of that extent, at or below every box.
/// Returns no cells (empty) unless at least half the boxes lie each within one cell (within
/// 1e-6 h; the rest are mostly slivers merged across a cell face): a
/// tetrahedral or Voronoi mesh has no such lattice. An octree mesh is grouped on its most
/// common cell size, each larger element in the cell of its centre.
std::vector<Eigen::Vector3i> latticeCells(const std::vector<Eigen::AlignedBox3d>& boxes);

/// Blocks (elements, or groups of a finer agglomeration) grouped, and the polynomial
/// displacements of each group (degree 1 or 2) expressed in its blocks' functions.
struct Agglomeration {
  /// Block b belongs to group parent[b]; group g's blocks are
  /// children[childStart[g] .. childStart[g + 1] - 1], in increasing order.
  std::vector<int> parent, childStart, children;
  /// Functions per displacement component of each group, numMonomials(degree): 4 (linear)
  /// or 10 (quadratic); and of each block, those that take part (the block's first ones):
  /// `functions`, or 4 when linear groups are grouped with quadratic functions.
  int functions = 4;
  int blockFunctions = 4;
  /// Group g's functions F_j = sum_a S_g(a, j) M_a, combinations of the scaled monomials
  /// M_a = ((x - C_g) / H_g)^a of degree <= the degree. On its block b, F_j = sum_i W_b(i, j)
  /// phi_i over the block's first `blockFunctions` functions phi_i, W_b column-major at
  /// weights[functions blockFunctions b]; the same for each displacement component. Exact
  /// when the blocks' functions span the groups' polynomials; linear blocks of quadratic
  /// groups take each monomial's Taylor part at their centre (value and gradient).
  std::vector<double> weights;
  /// S_g (functions x functions, column-major at spans[functions^2 g]): the identity, unless
  /// the group's blocks cannot tell some monomial combinations apart (linear blocks on a line
  /// or a plane: their Taylor parts vanish together). Then S_g's first ranks[g] columns are an
  /// orthonormal basis of the combinations they do tell apart (the eigenvectors of
  /// sum_b W_b^T W_b above kSpanTolerance of its largest eigenvalue) and the rest zero:
  /// unknowns that prolong to nothing, with a unit diagonal in galerkinBlocks() and zero
  /// right-hand side, so the coarse correction is exact on the rest.
  std::vector<double> spans;
  std::vector<int> ranks;
  /// Each group's centre C_g (the mean of its blocks' centres) and scale H_g, large enough
  /// that |x - C_g| <= H_g on each block (given |x - c_b| <= h_b there).
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> scales;
  /// Grouped by cells: group g's cell on the lattice twice as coarse as its blocks' (their
  /// cells divided by 2, rounded down), the cells the next agglomeration groups by; empty
  /// when grouped by pairing.
  std::vector<Eigen::Vector3i> cells;

  int groups() const { return static_cast<int>(centres.size()); }
};

/// Groups the blocks of a symmetric block matrix, given by block rows.
/// With `cells` (one per block: ElementFrames::cells for elements, Agglomeration::cells of the
/// finer agglomeration for its groups): the blocks of each 2 x 2 x 2 box of cells, split into
/// the connected components of their coupling within the box (blocks coupled: a stored block
/// between them with a nonzero entry), so a group never joins pieces that a cut separates;
/// nor two blocks of one cell, which a component can join around the edge of a finite cut
/// inside the box (pairs joined in block order, each unless it would put two blocks of one
/// cell in a group). On a hex grid these are the 2 x 2 x 2 blocks; on a sliced mesh the
/// elements of 2 x 2 x 2 grid cells (then 4 x 4 x 4, ...), compact however the surface or
/// the cuts clip them. Groups are numbered in the order of their first block.
/// Without (empty `cells`: no lattice), three rounds of greedy pairing: blocks, then pairs,
/// then pairs of pairs, round k pairing each group with its unpaired neighbour (a stored block)
/// best aligned with axis k (the line between their centres at most 60 degrees from the axis;
/// groups in order): 2 x 2 x 2 blocks on a hex grid, groups of up to 8 face neighbours of any
/// shape elsewhere.
/// `centres` and `scales` are the elements' frames; `bases` their T (ElementFrames::bases, of
/// which the top-left numMonomials(degree) block is used). `degree` (1 or 2) is that of the
/// groups' functions; the elements' first functions must span the polynomials of that degree.
/// Groups of groups: the overload below.
Agglomeration agglomerate(const BlockRows<double>& rows,
                          const std::vector<Eigen::Vector3d>& centres,
                          const std::vector<double>& scales,
                          const std::vector<Eigen::MatrixXd>& bases,
                          const std::vector<Eigen::Vector3i>& cells = {}, int degree = 1);

/// The groups of the groups of `finer` (whose Galerkin matrix `rows` has finer.functions per
/// component), by finer.cells if any, with functions of `degree` >= finer's degree: their
/// blocks' functions are finer's F_j (the spans S_g included).
Agglomeration agglomerate(const BlockRows<double>& rows, const Agglomeration& finer, int degree);

/// The Galerkin matrix P^T A P of the coarse space of `groups` (n = groups.functions per
/// component of each group, unknown (g, d, j) at 3 n g + n d + j) by block rows (one per
/// group, its blocks in increasing order), from A by block rows in double precision with
/// groups.blockFunctions per component (else std::invalid_argument), with a unit diagonal
/// for the unknowns that prolong to nothing (Agglomeration::spans). A coarse block whose
/// displacement components are uncoupled (BZ's) is stored component-diagonal (its three
/// diagonal n x n parts). Exactly symmetric.
BlockRows<double> galerkinBlocks(const Agglomeration& groups, const BlockRows<double>& rows);

/// The same in CSR (BlockRows::toSparse()), both triangles stored.
Eigen::SparseMatrix<double, Eigen::ColMajor, int> galerkinMatrix(const Agglomeration& groups,
                                                                 const BlockRows<double>& rows);

}  // namespace polydg
