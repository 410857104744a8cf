// Global assembly of the DG elasticity system: the roles of the faces in a problem, the
// penalty threshold, and the sparse stiffness matrix and load vector assembled from the local
// integrators element by element (in parallel, each element writing only its own rows).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/SparseCore>

#include "physics/dg/local_integrators.h"
#include "polydg/physics/dg/loads.h"
#include "polydg/physics/dg/material.h"
#include "util/uninitialized.h"

namespace polydg {

template <class T>
struct BlockRows;

/// The elements using a face: one (boundary) or two (interior), with their orientations.
struct FaceUses {
  std::array<ElementId, 2> element;
  std::array<bool, 2> reversed{false, false};  ///< the element uses the face reversed
  int count = 0;
};

/// The uses of every face, from the elements' face lists. Throws std::invalid_argument if a
/// face is used more than twice or twice with the same orientation (an invalid mesh).
FaceData<FaceUses> faceUses(const PolyMesh& mesh);

/// The role of every face in one problem.
struct FaceRoles {
  FaceData<FaceUses> uses;
  FaceData<FaceKind> kind;
  FaceData<int> dirichlet;  ///< index into LoadCase::dirichlet, -1 if none
  FaceData<int> traction;   ///< index into LoadCase::tractions, -1 if none
  /// Faces of each element with face terms (Interior or Dirichlet): c_K of the lifting.
  ElementData<int> coupledFaces;
  std::size_t dirichletFaces = 0, tractionFaces = 0, interiorFaces = 0;
};

/// Classifies the faces of `mesh` under `loads` (see LoadCase for precedence).
FaceRoles classifyFaces(const PolyMesh& mesh, const LoadCase& loads);

/// Share of each element's strain energy that the penalty threshold lets the IP consistency
/// terms consume (theta below); the rest, 2 mu (1 - theta) |eps(u)|^2, is the coercivity margin.
/// 0.9 rather than the textbook 0.5: a smaller penalty is markedly more accurate for p = 1
/// (B1 L2 error 2.3e-4 instead of 3.0e-4 at n = 8, rate 1.96 instead of 1.75 from 8 to 16).
inline constexpr double kConsistencyEnergyShare = 0.9;

/// The smallest global eta for which the IP form is guaranteed coercive, so that the stiffness
/// matrix with Dirichlet conditions is SPD:  eta_min = max_K 2 tau_K / theta, where
///   tau_K = max over strains eps in Sym(3) (x) P_{p-1}(K) of
///           sum_{F of K with face terms} w_F^2 (vol(K) / a_K) |eps n_F|^2_F / |eps|^2_K
/// (a generalized eigenvalue of size 6 numMonomials(p-1), from liftingFaceGram()), a_K the mean
/// area of K's faces with face terms (meanCoupledFaceAreas()), w_F = 1/2 on interior and 1 on
/// Dirichlet faces, theta = kConsistencyEnergyShare. Derivation: the consistency terms are
/// bounded by sum_K sum_F 4 mu w_F |eps(u_K) n|_F |[u]|_F; Young's inequality with weights
/// mu s_K a_K / vol(K), s_K = 2 tau_K / theta, bounds them by theta 2 mu |eps(u)|^2 +
/// sum_F mu (sum_K s_K a_K / vol(K)) |[u]|^2_F, which the penalty mu eta_F |[u]|^2_F covers
/// when eta >= max_K s_K (facePenalty() with FormCoefficients::elementFaceArea).
/// Why a_K and not each face's own area (the weight area(F) / vol(K) of eq. 7): with it, each
/// face's term above is about |eps n_F|^2 / |eps|^2 whatever the face's size, so tau_K grew
/// with the number of faces: an element under a clamp with 500 surface triangles as Dirichlet
/// faces got s_K = 580 against a cube's 2.8 at p = 1, and with it the penalty on all its faces.
/// With a_K the sum is an area-weighted mean, bounded by the shape and not the face count; on
/// a hex grid, where every face of an element has the same area, nothing changes. The lambda
/// part is positive semi-definite by itself (faceRows()). Dimensionless: independent of the
/// material, the mesh scale and position. For unit cubes and p = 1, 2, 3 it gives 2.8, 9.6,
/// 20.7 (set by the elements next to Dirichlet faces); Cholesky already succeeds at about half
/// of these. Returns 0 for a mesh without coupled faces.
double penaltyThreshold(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                        const FaceRoles& roles);

/// The mean area a_K of each element's faces with face terms (Interior or Dirichlet, of
/// positive area); 0 for an element without them.
ElementData<double> meanCoupledFaceAreas(const PolyMesh& mesh, const MomentCache& moments,
                                         const FaceRoles& roles);

/// The per-element bounds s_K = 2 tau_K / theta of penaltyThreshold() (0 for an element
/// without coupled faces). The derivation there needs, face by face, only
/// eta_F >= sum_{K of F} s_K a_K / vol(K): with FormCoefficients::elementEta = s_K the IP
/// form is coercive while each face's penalty follows its own two elements, not the worst
/// element of the mesh. `meanArea`: meanCoupledFaceAreas() of the same mesh and roles.
ElementData<double> elementPenaltyThresholds(const PolyMesh& mesh, const DgBasis& basis,
                                             const MomentCache& moments, const FaceRoles& roles,
                                             const ElementData<double>& meanArea);

/// A symmetric sparse system K U = F. Element e's DOFs are the contiguous range
/// [e * blockSize, (e + 1) * blockSize), in the order d * n + i (component d, function i).
/// The matrix stores both triangles (column-major; by symmetry its columns are its rows).
struct LinearSystem {
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> matrix;
  Eigen::VectorXd rhs;
  int blockSize = 0;
};

/// The element and face matrices of one form, precomputed as in the thesis (Kaufmann 2013,
/// sec. 4.4, "Assembly": K_K per element and K_f per face, the transposed face blocks not
/// stored): the thesis's "integration" phase, which assembleStiffness(const LocalMatrices&)
/// then accumulates into K (its "assembly" phase). Per element e:
///   - the diagonal block: element stiffness plus the self terms of e's coupled faces,
///     3n x 3n column-major, symmetric;
///   - for each neighbour f > e (coupled through interior faces), the coupling block of e's
///     rows against f's columns, summed over their common faces, 3n x 3n row-major; the block
///     of f's rows against e's columns is its transpose, never computed.
struct LocalMatrices {
  int blockSize = 0;
  int functions = 0;                       ///< n, functions per component
  bool componentDiagonalCoupling = false;  ///< BZ: coupling blocks couple equal components only
  /// Neighbours of each element through interior faces, sorted, the element itself included.
  std::vector<std::vector<std::uint32_t>> neighbours;
  UninitializedVector<double> diagonal;  ///< element e's block at e * blockSize^2
  /// Element e's coupling blocks, one per neighbour f > e in order (greaterNeighbours()), start
  /// at block couplingStart[e] (each blockSize^2 values); couplingStart[#elements] is the
  /// number of blocks stored. In element order, except after updateSplitLocalMatrices(), which
  /// appends the blocks it recomputes and leaves the old ones unused.
  std::vector<std::size_t> couplingStart;
  UninitializedVector<double> coupling;
};

/// Neighbours of each element (sorted, with itself) through coupled interior faces.
std::vector<std::vector<std::uint32_t>> coupledNeighbours(const PolyMesh& mesh,
                                                          const FaceRoles& roles);

/// How many of element i's neighbours come after it: the number of its coupling blocks.
inline std::size_t greaterNeighbours(const std::vector<std::vector<std::uint32_t>>& neighbours,
                                     std::size_t i) {
  const auto& b = neighbours[i];
  return static_cast<std::size_t>(
      b.end() - std::upper_bound(b.begin(), b.end(), static_cast<std::uint32_t>(i)));
}

/// The element and face matrices of `form` (both IP and BZ), in parallel over elements.
LocalMatrices localMatrices(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                            const FaceRoles& roles, const FormCoefficients& form);

/// The local matrices of a form split by the element whose strain each term holds, for
/// stiffness warping (Kaufmann et al. 2008, section 7; physics/dynamics/dynamics.h). Their sum,
/// block by block, is localMatrices(); all three have its layout (the same neighbours).
struct SplitLocalMatrices {
  /// Strain of the rows' element: the element stiffness and the face terms of the diagonal
  /// blocks with strain (K_K, K_f1 and K_f2 of the element with itself), and the symmetry
  /// terms of the coupling blocks (K_f2 of the row element); with the element's own lifting
  /// terms. Without the terms of Dirichlet faces, which are apart (dirichletTrial, -Test).
  LocalMatrices rowStrain;
  /// Strain of the columns' element: the consistency terms of the coupling blocks (K_f1 of the
  /// column element) and its lifting term; the diagonal blocks are zero.
  LocalMatrices columnStrain;
  /// No strain: the jump penalty (K_f3), not warped.
  LocalMatrices jumps;
  /// IP: the lifting terms of each neighbour L in element K's diagonal block (they complete
  /// L's lambda terms, warped with L's rotation): for element K, one block (3n x 3n,
  /// column-major) per neighbour in the order of `neighbours` without K, from block
  /// neighbourStart[K] (laid out as couplingStart). Zero for BZ.
  std::vector<std::size_t> neighbourStart;
  UninitializedVector<double> neighbourLifting;
  /// IP, per element (3n x 3n, column-major): the terms of its Dirichlet faces with the strain
  /// of the trial function (consistency) and with that of the test function (symmetry, and
  /// the lifting). Apart because the jump on a Dirichlet face is against the fixed outside:
  /// warped, it is R^T (X - X0) = R^T U, where an interior face's is R^T X - X0 on both sides.
  UninitializedVector<double> dirichletTrial, dirichletTest;
};

SplitLocalMatrices splitLocalMatrices(const PolyMesh& mesh, const DgBasis& basis,
                                      const MomentCache& moments, const FaceRoles& roles,
                                      const FormCoefficients& form);

/// After an edit of the mesh `split` was made for: the split matrices of `mesh`, in place,
/// with the rows recomputed only for the elements that need it and the others' kept: an
/// element keeps its rows if it had its id before, is not `fresh` (the caller's mark for an
/// element whose shape, faces, basis or penalty changed), has the same neighbours as before and
/// none of them is fresh. Recomputed coupling and lifting blocks are appended; once the unused
/// ones outnumber those in use, everything is laid out and computed again. Returns the number
/// of elements whose rows were computed.
std::size_t updateSplitLocalMatrices(SplitLocalMatrices& split, const PolyMesh& mesh,
                                     const DgBasis& basis, const MomentCache& moments,
                                     const FaceRoles& roles, const FormCoefficients& form,
                                     const std::vector<char>& fresh);

/// The rows of `elements` of the split matrices, written where `split`'s layout (neighbours,
/// couplingStart, neighbourStart; arrays sized) puts them: the three parts' diagonal and
/// coupling blocks, the neighbours' lifting blocks and the Dirichlet blocks.
void writeSplitRows(SplitLocalMatrices& split, const PolyMesh& mesh, const DgBasis& basis,
                    const MomentCache& moments, const FaceRoles& roles,
                    const FormCoefficients& form, std::span<const std::uint32_t> elements);

/// K from the local matrices: both triangles, each column written once, in parallel over
/// elements. With BZ, blocks between neighbours couple equal components only and are stored
/// so (the paper's sparser BZ matrices).
Eigen::SparseMatrix<double, Eigen::ColMajor, int> assembleStiffness(const LocalMatrices& local);

/// K of `form` (localMatrices()' terms) by element block rows (BlockRows, double precision),
/// assembled straight from each element's rows: the one copy of K an iterative solve needs,
/// 8 bytes per nonzero, with neither the local matrices nor a CSR matrix alongside. BZ's
/// neighbour blocks are stored component-diagonal, as assembleStiffness() stores them.
BlockRows<double> assembleBlockRows(const PolyMesh& mesh, const DgBasis& basis,
                                    const MomentCache& moments, const FaceRoles& roles,
                                    const FormCoefficients& form);

/// Block rows of the local matrices' layout (the same neighbours), values unset: for a time
/// step's matrix written straight into them (CorotatedStiffness::assemble).
BlockRows<double> blockRowsLayout(const LocalMatrices& local);

/// Writes K from `local` into `matrix`, which has the pattern assembleStiffness() made for
/// local matrices of the same layout: new values (a warped stiffness, a time step's system
/// matrix) without a new matrix. Throws std::invalid_argument for another size or pattern.
void refillStiffness(const LocalMatrices& local,
                     Eigen::SparseMatrix<double, Eigen::ColMajor, int>& matrix);

/// K of `form`: localMatrices() then assembleStiffness().
Eigen::SparseMatrix<double, Eigen::ColMajor, int> assembleStiffness(const PolyMesh& mesh,
                                                                    const DgBasis& basis,
                                                                    const MomentCache& moments,
                                                                    const FaceRoles& roles,
                                                                    const FormCoefficients& form);

/// F: body forces (density * gravity exactly, `bodyForce` by element quadrature of degree
/// `quadratureDegree`), tractions, and the Dirichlet terms of `form`:
///   int_F mu eta_F g.v - (sigma(v) n).g + lambda c_K (R g.n, R v.n)      (IP)
///   int_F mu eta_F g.v                                                   (BZ)
/// with g integrated by face quadrature of degree `quadratureDegree`. Throws InputError if F
/// overflows (not finite).
Eigen::VectorXd assembleLoad(const PolyMesh& mesh, const DgBasis& basis, const MomentCache& moments,
                             const FaceRoles& roles, const FormCoefficients& form,
                             const Material& material, const LoadCase& loads, int quadratureDegree);

}  // namespace polydg
