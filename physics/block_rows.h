// A copy of a symmetric DG matrix by element block rows, with no index per entry, for the
// memory-bound kernels of the iterative solver: the p-multigrid smoother (single precision)
// and the conjugate gradients' matrix-vector product (double precision).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace polydg {

/// Element e's rows (block size bs = 3n, e's DOFs [e bs, (e + 1) bs)) as blocks against the
/// elements it couples with: slots start[e] .. start[e + 1] - 1, slot k the block against
/// element element[k], its values from values[offset[k]]. A slot is either full (bs x bs,
/// column-major) or, when the block couples equal displacement components only (BZ's
/// neighbour blocks), component-diagonal: its three n x n diagonal blocks one after the other,
/// each column-major (a third of the values).
template <class T>
struct BlockRows {
  int bs = 0, n = 0;
  std::vector<int> start, element;
  std::vector<std::size_t> offset;
  std::vector<std::uint8_t> diagonal;  ///< 1: component-diagonal slot
  std::vector<T> values;

  /// Builds the rows of `a` (symmetric, both triangles stored, columns sorted) with n
  /// functions per component. Returns false, and keeps no values, if the blocks would store
  /// more than `maxRatio` times the matrix's nonzeros (a pattern too sparse for blocks).
  bool build(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, int functions,
             double maxRatio);

  /// The same rows in this precision, from `other`'s layout and values (no pass over a
  /// sparse matrix).
  template <class U>
  void convertFrom(const BlockRows<U>& other) {
    bs = other.bs;
    n = other.n;
    start = other.start;
    element = other.element;
    offset = other.offset;
    diagonal = other.diagonal;
    values.resize(other.values.size());
    std::transform(other.values.begin(), other.values.end(), values.begin(),
                   [](U v) { return static_cast<T>(v); });
  }

  /// The diagonal block of element e, bs x bs column-major (a full slot).
  const T* diagonalBlock(int e) const;

  /// out = (A x)_e, the rows of element e (bs values).
  void rowProduct(int e, const double* x, double* out) const {
    std::fill(out, out + bs, 0.0);
    subtractRowProduct(e, x, out);
    for (int c = 0; c < bs; ++c) out[c] = -out[c];
  }

  /// out -= (A x)_e, the rows of element e (bs values).
  void subtractRowProduct(int e, const double* x, double* out) const {
    // Compile-time sizes for the DG degrees (n = 1, 4, 10, 20): the short column loops unroll
    // and vectorize; B2, p = 1: ... faster than with the sizes known at run time.
    switch (n) {
      case 1: return subtractRowProductOf<1>(e, x, out);
      case 4: return subtractRowProductOf<4>(e, x, out);
      case 10: return subtractRowProductOf<10>(e, x, out);
      case 20: return subtractRowProductOf<20>(e, x, out);
      default: return subtractRowProductOf<0>(e, x, out);
    }
  }

 private:
  /// subtractRowProduct() with N functions per component (0: n, known at run time only).
  template <int N>
  void subtractRowProductOf(int e, const double* x, double* out) const {
    const int nn = N > 0 ? N : n, bb = 3 * nn;
    for (int k = start[static_cast<std::size_t>(e)]; k < start[static_cast<std::size_t>(e) + 1];
         ++k) {
      const std::size_t slot = static_cast<std::size_t>(k);
      const T* block = values.data() + offset[slot];
      const double* xf = x + static_cast<std::ptrdiff_t>(element[slot]) * bb;
      // Column by column: the inner loop has no reduction and vectorizes.
      if (diagonal[slot]) {
        for (int d = 0; d < 3; ++d)
          for (int j = 0; j < nn; ++j) {
            const T* column = block + (d * nn + j) * nn;
            const double xj = xf[d * nn + j];
            double* od = out + d * nn;
            for (int i = 0; i < nn; ++i) od[i] -= static_cast<double>(column[i]) * xj;
          }
        continue;
      }
      for (int d = 0; d < bb; ++d) {
        const T* column = block + d * bb;
        const double xd = xf[d];
        for (int c = 0; c < bb; ++c) out[c] -= static_cast<double>(column[c]) * xd;
      }
    }
  }

 public:
};

extern template struct BlockRows<float>;
extern template struct BlockRows<double>;

}  // namespace polydg
