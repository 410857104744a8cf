// A high-resolution surface riding on the discontinuous DG displacement without gaps: the
// moving-least-squares (MLS) embedding of Kaufmann et al. 2008, section 8 (Kaufmann 2013,
// section 4.5), with its weights precomputed once (eq. 19) and updated only near a cut.
//
// Samples. Every mesh vertex gives one sample per connected piece of the body that holds it:
// the mean of u|_K(vertex) over the piece's elements K at that vertex (eq. 17, taken per side of
// a cut). For degree 2 and 3 every face centre (mean of its elements' values) and every element
// centre are samples too, so that the fit follows higher-order fields. Each sample s has the
// support radius R_s = support * the largest half bounding-box diagonal of its elements.
//
// Weights. A point x takes the samples of its own piece (the piece of the element containing
// it) with |x - x_s| < R_s and fits an affine field minimizing
//   sum_s theta_s(|x - x_s|) |a^T p(x_s) - u_s|^2,  p(y) = (1, (y - x) / H)   (eq. 18)
// with the truncated Gaussian theta_s(r) = exp(-(2r/R_s)^2) - exp(-4) for r < R_s (0 beyond:
// continuous at the support's edge), H the largest radius used (a local, scaled frame). Its
// value at x is sum_s phi_s(x) u_s with phi_s = theta_s p_s^T A^{-1} e_0: exact for every
// affine field (hence rigid motions), and continuous across elements. Too few samples (A
// singular: reciprocal condition below kMinimumConditioning) widen that point's supports.
// Samples of the other side of a cut never enter (the paper does not say this).
//
// Storage: S (samples x scalar coefficients) and Phi (points x samples), both sparse, for
// updates; W = Phi S, eq. (19)'s weight matrix, for use: the displacement of the points is W U
// per component, and a point's W row is what its contact force acts through.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "polydg/physics/dg/dg_basis.h"

namespace polydg {

enum class EmbeddingMethod {
  /// Moving least squares over the samples around the point (section 8): smooth.
  Mls,
  /// The comparison of section 8: eq. (17) at the element vertices, then per element the
  /// affine least-squares fit of its own vertices' values (linear interpolation on a
  /// tetrahedron): continuous only where neighbouring fits agree, kinks at element faces.
  ElementLinear,
  /// Nodal contact points (section 9's cheap option): the points are the mesh's boundary
  /// vertices, one per piece that holds the vertex (both sides of a cut), each followed by its
  /// eq. (17) mean. Made by SurfaceEmbedding::boundaryNodes().
  Nodal,
};

struct EmbeddingOptions {
  EmbeddingMethod method = EmbeddingMethod::Mls;
  /// Support radius in units of the largest half bounding-box diagonal of a sample's elements
  /// (for a cube of edge h, 2 reaches 1.73 h: about 20 vertex samples per point).
  double support = 2.0;
};

/// What an update after a cut did.
struct EmbeddingUpdate {
  std::size_t recomputed = 0;  ///< points whose weights were computed again
  std::size_t kept = 0;        ///< points whose weights were only renumbered
  double seconds = 0.0;
};

/// One row of W by elements: the elements a point's weights reach, ascending, and for each the
/// weights of its n scalar functions (n values an element, zero where a function has none).
struct WeightBlocks {
  std::span<const std::uint32_t> elements;
  std::span<const double> values;
};

/// The embedding of a point set (a surface's vertices) into a DG mesh. Holds no reference to
/// the mesh or basis after construction.
class SurfaceEmbedding {
 public:
  /// The smallest reciprocal condition number of a point's 4 x 4 moment matrix A before its
  /// supports are widened (by 1.5, up to all samples of its piece).
  static constexpr double kMinimumConditioning = 1e-10;

  /// Computes the samples and every point's weights for `basis` (built on `mesh`). Points
  /// outside the mesh follow the nearest element's piece (counted by outside()).
  SurfaceEmbedding(const PolyMesh& mesh, const DgBasis& basis, std::vector<Vec3> points,
                   const EmbeddingOptions& options = {});

  /// The mesh's boundary vertices as points, one per piece holding the vertex, each taking
  /// its own eq. (17) sample; `areas` receives each point's share of the boundary area (a
  /// boundary face's area split equally among its vertices).
  static SurfaceEmbedding boundaryNodes(const PolyMesh& mesh, const DgBasis& basis,
                                        std::vector<double>& areas);

  std::size_t numPoints() const { return points_.size(); }
  std::size_t numSamples() const { return samplePositions_.size(); }
  const std::vector<Vec3>& points() const { return points_; }
  const EmbeddingOptions& options() const { return options_; }
  /// The piece (connected component of the mesh through interior faces) of every point.
  const std::vector<std::uint32_t>& pieces() const { return pointPiece_; }
  std::size_t numPieces() const { return numPieces_; }
  /// Points in no element (they follow the nearest one).
  std::size_t outside() const { return outside_; }
  /// Scalar functions per element of the basis the weights were computed for, and elements.
  int basisSize() const { return n_; }
  std::size_t numElements() const { return numElements_; }
  /// The value of each element's first basis function, a constant: a uniform displacement t
  /// has the coefficient t_d / constantValues()[e] on it and 0 on the others.
  const std::vector<double>& constantValues() const { return constant_; }

  /// The displacement of every point for DG coefficients in LinearSystem's layout
  /// (U[(e * 3 + d) * n + i]); #points by 3.
  Eigen::Matrix<double, Eigen::Dynamic, 3> displacements(const Eigen::VectorXd& coefficients) const;
  /// The displacement of point p alone, the same sum as displacements() row p.
  Vec3 displacement(std::size_t p, const Eigen::VectorXd& coefficients) const;
  /// Point p displaced by `coefficients`.
  Vec3 position(std::size_t p, const Eigen::VectorXd& coefficients) const {
    return points_[p] + displacement(p, coefficients);
  }

  const std::vector<Vec3>& samplePositions() const { return samplePositions_; }
  /// Row p of W = Phi S (eq. 19) by elements: the weight W_i(x_p) of element e's function i is
  /// values[k * n + i] where elements[k] = e; component d of the point's displacement is
  /// sum W_i U[(e * 3 + d) * n + i]. Stored so: a point's weights cover all n functions of
  /// each element its samples lie in, and an element's block is read as one short vector.
  WeightBlocks weightBlocks(std::size_t p) const;
  /// W, #points by (elements * n), row-major (its nonzero weights).
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> weights() const;
  /// Weights W stores (n an element block: what a surface update reads), and the nonzeros of
  /// Phi and S (kept for updates).
  std::size_t weightNonzeros() const { return weightValues_.size(); }
  std::size_t storedNonzeros() const { return pointValues_.size() + sampleValues_.size(); }

  /// After an edit of the mesh: `source[e]` is the old element new element e was made from
  /// (invalid if it was merged from several). Samples are made again (they are cheap); a point
  /// keeps its weights (renumbered) if all its samples are unchanged (same position, support
  /// and values through the renumbering), lie in one piece, and no new sample reaches it; the
  /// others are computed again. `basis` is the new mesh's, of the same degree and kind.
  /// Throws std::logic_error for boundary nodes (their point set changes: make them again).
  EmbeddingUpdate update(const PolyMesh& mesh, const DgBasis& basis,
                         std::span<const ElementId> source);

  double setupSeconds() const { return setupSeconds_; }

 private:
  struct Samples;

  static Samples clustered(Samples&& raw);
  Samples makeSamples(const PolyMesh& mesh, const DgBasis& basis) const;
  SurfaceEmbedding() = default;
  void adopt(Samples&& samples);
  struct Rows;
  /// Locates and computes the rows of points `which` (pieces, support factors and Phi rows).
  Rows computeRows(const PolyMesh& mesh, const Samples& samples,
                   std::span<const std::uint32_t> which);
  /// The element each of points `which` lies in, by their bounding boxes and, where those
  /// disagree, a geometric test; a point in none takes the nearest box's (rows.outside).
  std::vector<std::uint32_t> locatePoints(const PolyMesh& mesh, const Samples& samples,
                                          std::span<const std::uint32_t> which, Rows& rows) const;
  /// The Phi row of point x in `element` and `piece` (eq. 18), into `row`; returns the factor
  /// its supports were widened by.
  double fitRow(const Samples& samples, const Vec3& x, std::uint32_t element, std::uint32_t piece,
                std::vector<std::pair<std::uint32_t, double>>& row) const;
  /// update()'s steps. Each old sample's new twin (same position, support and row through the
  /// renumbering `source`), or -1; `used` marks the new samples that have one.
  std::vector<std::int64_t> matchSamples(const Samples& samples, std::span<const ElementId> source,
                                         std::vector<char>& used) const;
  /// The points that keep their rows: all their samples matched, in one piece (written to
  /// `newPiece`), and no new sample reaching them.
  std::vector<char> keptPoints(const Samples& samples, const std::vector<std::int64_t>& matched,
                               const std::vector<char>& used,
                               std::vector<std::uint32_t>& newPiece) const;
  /// Phi from the kept points' rows (renumbered) and the others' new `rows`.
  void mergeRows(const std::vector<char>& keep, const std::vector<std::int64_t>& matched,
                 const Rows& rows, std::vector<std::uint32_t> newPiece);

  EmbeddingOptions options_;
  std::vector<Vec3> points_;
  int n_ = 0;
  std::size_t numPieces_ = 0, outside_ = 0;
  std::vector<std::uint32_t> pointPiece_;
  std::vector<float> pointWidening_;
  std::vector<char> pointOutside_;  ///< factor on the supports a point needed (>= 1)
  // Samples: positions, radii, pieces, and S in CSR form.
  std::vector<Vec3> samplePositions_;
  std::vector<double> sampleRadius_;
  std::vector<std::uint32_t> samplePiece_;
  std::vector<std::size_t> sampleStart_;
  std::vector<std::uint32_t> sampleColumns_;
  std::vector<double> sampleValues_;
  // Phi in CSR form.
  std::vector<std::size_t> pointStart_;
  std::vector<std::uint32_t> pointColumns_;
  std::vector<double> pointValues_;
  // W = Phi S by element blocks: point p's blocks are weightStart_[p] .. weightStart_[p + 1],
  // block k of element weightElements_[k] with n weights from weightValues_[k * n].
  std::vector<std::size_t> weightStart_;
  std::vector<std::uint32_t> weightElements_;
  std::vector<double> weightValues_;
  std::size_t numElements_ = 0;
  std::vector<double> constant_;  ///< phi_0 of each element
  void computeWeights();
  double setupSeconds_ = 0.0;
};

}  // namespace polydg
