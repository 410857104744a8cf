// The corotated DG stiffness (Kaufmann et al. 2008, section 7): each element's rotation from
// the polar decomposition of its mean deformation gradient, and the stiffness warped by those
// rotations, applied to a vector or assembled with the mass into a time step's matrix.
//
// The stiffness is split by the element whose strain each term holds (splitLocalMatrices():
// K_K and K_f1, K_f2 split by side, the penalty K_f3 apart); a block B of rows A, columns C with
// strain of element S acts as R_S B (R_S^T X_C - X0_C), the penalty as B (X_C - X0_C), where
// X = X0 + U are the coefficients of the deformed positions and X0 those of the undeformed ones
// (x - o, o the body's reference point: the identity map, exact in every element's linear
// functions). A rigid motion of the whole body thus gives no elastic force.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "physics/dg/assembly.h"

namespace polydg {

/// The rotation of the polar decomposition F = R S (det R = +1; for det F <= 0 the closest
/// rotation, flipping the direction of the smallest singular value).
Eigen::Matrix3d polarRotation(const Eigen::Matrix3d& f);

/// The split element and face blocks of a mesh's DG stiffness, warped by element rotations.
/// Vectors are in LinearSystem's layout (element blocks of 3n, component-major).
class CorotatedStiffness {
 public:
  /// `parts` from splitLocalMatrices() of `basis`; `origin` is o of X0 (the body's undeformed
  /// centre of mass keeps the coordinates bounded far from the world's origin). Without
  /// `corotational` every rotation is the identity: the linear stiffness.
  CorotatedStiffness(const DgBasis& basis, const MomentCache& moments, SplitLocalMatrices parts,
                     const Vec3& origin, bool corotational);

  bool corotational() const { return corotational_; }
  /// X0: the coefficients of x - origin.
  const Eigen::VectorXd& undeformed() const { return x0_; }
  /// The layout of the assembled blocks (the penalty's: every coupled pair of elements).
  const LocalMatrices& layout() const { return parts_.jumps; }
  /// Gives the split matrices back (for updateSplitLocalMatrices() after an edit); the
  /// stiffness is empty afterwards.
  SplitLocalMatrices release() && { return std::move(parts_); }

  /// Element i's mean deformation gradient I + (1/|K|) int_K grad u for the displacement `u`.
  Eigen::Matrix3d deformationGradient(std::size_t i, const Eigen::VectorXd& u) const;
  /// Every element's rotation for the displacement `u` (identities without corotation).
  std::vector<Eigen::Matrix3d> rotations(const Eigen::VectorXd& u) const;

  /// out = sum over blocks of R_S B (R_S^T x_C - z_C) (z null: 0), and if `energy`, the form's
  /// energy 1/2 sum (R_S^T x_A - z_A) . B (R_S^T x_C - z_C). With x = X0 + U and z = X0 this is
  /// the elastic force f(U); with z null, K_w x.
  void product(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
               const Eigen::VectorXd* z, Eigen::VectorXd& out, double* energy) const;

  /// f(U) and its energy (product() with x = X0 + U and z = X0) and the blocks of cM M + cK
  /// K_w into `rows` (assemble()) in one pass: each split block is read once, its force terms
  /// while it is in cache from warping it. A corotated step needs both at the same rotations.
  void forceAndAssemble(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& u,
                        Eigen::VectorXd& force, double& energy, const std::vector<double>& mass,
                        double cM, double cK, BlockRows<double>& rows) const;

  /// The blocks of cM M + cK K_w into `system` (which has layout()'s pattern): `mass` holds each
  /// element's n x n scalar mass block, column-major.
  void assemble(const std::vector<Eigen::Matrix3d>& r, const std::vector<double>& mass, double cM,
                double cK, LocalMatrices& system) const;
  /// The same straight into block rows of layout()'s pattern (blockRowsLayout(layout())).
  void assemble(const std::vector<Eigen::Matrix3d>& r, const std::vector<double>& mass, double cM,
                double cK, BlockRows<double>& rows) const;

 private:
  /// One block of an element's rows: against element `other`, read from `block` of the split
  /// matrices (diagonal: the element's own; else a coupling block, transposed when stored by
  /// the other element).
  struct RowSlot {
    std::uint32_t other = 0;
    std::size_t block = 0;  ///< diagonal: the element; coupling: the coupling block's index
    bool diagonal = false;
    bool transposed = false;
  };
  /// The parts of a block of row element i: pointers, layouts and the element whose rotation
  /// warps it (-1: none).
  struct Part {
    const double* b;
    bool columnMajor;  ///< else row-major (read transposed: the other layout)
    std::int64_t source;
  };

  template <int N>
  class BlockTerms;

  void buildSlots();
  void elementTerms(const DgBasis& basis, const MomentCache& moments, const Vec3& origin);
  int partsOf(std::size_t i, const RowSlot& s, Part out[3]) const;
  /// Row i's terms of product() into `out`, and their energy, but those of the coupling blocks
  /// stored by a smaller neighbour; the blocks i stores give the other element's row's terms
  /// too, at transposedTerms[3n * block].
  template <int N>
  double rowTerms(BlockTerms<N>& terms, std::size_t i, double* out, double* transposedTerms) const;
  /// product()'s rows (rowTerms() with the coupling blocks read once, their other row's terms
  /// added in a second pass), its energy returned; eachElement(i) runs in element i's task
  /// right before its row.
  template <int N, class EachElement>
  double sumRows(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
                 const Eigen::VectorXd* z, bool energy, Eigen::VectorXd& out,
                 const EachElement& eachElement) const;
  template <int N>
  void productOf(const std::vector<Eigen::Matrix3d>& r, const Eigen::VectorXd& x,
                 const Eigen::VectorXd* z, Eigen::VectorXd& out, double* energy) const;
  /// each(i, buffer) for every element i in parallel, `buffer` a scratch vector of the task.
  template <class Each>
  void assembleOf(const Each& each) const;
  /// Element i's blocks of cM M + cK K_w (elementBlocks()) into `buffer`, then into its row of
  /// `rows` and, transposed, its neighbours' rows (writeElementRows()).
  template <int N>
  void elementRows(const std::vector<Eigen::Matrix3d>& r, const std::vector<double>& mass,
                   double cM, double cK, std::size_t i, std::vector<double>& buffer,
                   BlockRows<double>& rows) const;
  /// Element i's blocks of cM M + cK K_w: its diagonal block into `d` (column-major), its
  /// coupling blocks with neighbours f > i, one after the other, into `c` (row-major).
  template <int N>
  void elementBlocks(const std::vector<Eigen::Matrix3d>& r, const std::vector<double>& mass,
                     double cM, double cK, std::size_t i, double* d, double* c) const;

  SplitLocalMatrices parts_;
  bool corotational_ = true;
  int degree_ = 1;
  int n_ = 0, bs_ = 0;
  std::size_t ne_ = 0;
  std::vector<std::size_t> rowStart_;
  std::vector<RowSlot> slots_;
  std::vector<std::uint8_t> clamped_;  ///< 1: the element has a Dirichlet face
  std::vector<double> gradients_;      ///< (1/|K|) int d_k phi_i at k * n + i, 3n per element
  Eigen::VectorXd x0_;
};

}  // namespace polydg
