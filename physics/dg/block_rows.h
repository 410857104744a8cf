// A copy of a symmetric DG matrix by element block rows, with no index per entry, for the
// memory-bound kernels of the iterative solver: the p-multigrid smoother (single precision)
// and the conjugate gradients' matrix-vector product (double precision).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "util/uninitialized.h"

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
  UninitializedVector<T> values;

  /// Builds the rows of `a` (symmetric, both triangles stored, columns sorted) with n
  /// functions per component. Returns false, and keeps no values, if the blocks would store
  /// more than `maxRatio` times the matrix's nonzeros (a pattern too sparse for blocks).
  bool build(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& a, int functions,
             double maxRatio);

  /// The same rows in this precision, from `other`'s layout and values (no pass over a
  /// sparse matrix).
  template <class U>
  void convertFrom(const BlockRows<U>& other) {
    copyPattern(other);
    offset = other.offset;
    values.resize(other.values.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, values.size(), 1 << 16),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                          values[i] = static_cast<T>(other.values[i]);
                      });
  }

  /// `other`'s pattern (block size, slots and their kinds), no values: what a smoother's
  /// grouping and colouring read before convertInOrder() fills the values.
  template <class U>
  void copyPattern(const BlockRows<U>& other) {
    bs = other.bs;
    n = other.n;
    start = other.start;
    element = other.element;
    diagonal = other.diagonal;
    offset.clear();
    values = UninitializedVector<T>();
  }

  /// `other`'s values (the pattern copyPattern() took) in this precision, laid out as
  /// layOutInOrder(order) lays them: the conversion and the layout in one pass.
  template <class U>
  void convertInOrder(const BlockRows<U>& other, const std::vector<int>& order) {
    std::size_t total = 0;
    offset = offsetsInOrder(order, other.offset.size(), total);
    values.resize(total);
    tbb::parallel_for(std::size_t(0), order.size(), [&](std::size_t i) {
      const auto e = static_cast<std::size_t>(order[i]);
      for (auto k = static_cast<std::size_t>(start[e]); k < static_cast<std::size_t>(start[e + 1]);
           ++k) {
        const U* from = other.values.data() + other.offset[k];
        T* to = values.data() + offset[k];
        for (std::size_t j = 0, size = slotSize(k); j < size; ++j) to[j] = static_cast<T>(from[j]);
      }
    });
  }

  /// The offsets of `count` slots (the slots, and the end of the values if kept) when the
  /// rows of the elements in `order` (each once) follow one another in that order; `total`:
  /// the values they hold.
  std::vector<std::size_t> offsetsInOrder(const std::vector<int>& order, std::size_t count,
                                          std::size_t& total) const;

  /// Lays the values out again so that the rows of the elements in `order` (each element once)
  /// follow one another in that order: a smoother that visits elements colour by colour then
  /// streams its blocks instead of skipping every other row (a row of 7 single-precision
  /// blocks of p = 1 is 4 KB, the span a hardware prefetcher stops at).
  void layOutInOrder(const std::vector<int>& order);

  /// The values slot k stores: bs^2, or 3 n^2 if component-diagonal.
  std::size_t slotSize(std::size_t k) const {
    return static_cast<std::size_t>(diagonal[k] ? 3 * n * n : bs * bs);
  }

  /// The diagonal block of element e, bs x bs column-major (a full slot).
  const T* diagonalBlock(int e) const;

  /// Writes slot k's block (rows: the row element's DOFs, columns: element[k]'s) into `out`,
  /// column-major with leading dimension `ld` >= bs. A component-diagonal slot writes its three
  /// n x n diagonal blocks only; the entries between them are left as they are.
  void copySlot(std::size_t k, double* out, int ld) const {
    const T* block = values.data() + offset[k];
    if (diagonal[k]) {
      for (int d = 0; d < 3; ++d)
        for (int j = 0; j < n; ++j)
          for (int i = 0; i < n; ++i)
            out[static_cast<std::ptrdiff_t>(d * n + j) * ld + d * n + i] =
                static_cast<double>(block[d * n * n + j * n + i]);
      return;
    }
    for (int j = 0; j < bs; ++j)
      for (int i = 0; i < bs; ++i)
        out[static_cast<std::ptrdiff_t>(j) * ld + i] = static_cast<double>(block[j * bs + i]);
  }

  /// Elements (block rows), and the entries stored: the nonzeros of the CSR matrix with the
  /// same pattern (assembleStiffness()'s).
  int elements() const { return start.empty() ? 0 : static_cast<int>(start.size()) - 1; }
  std::size_t entries() const { return values.size(); }

  /// The same matrix in CSR (both triangles, columns sorted), with assembleStiffness()'s
  /// pattern: every stored entry, zeros included.
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> toSparse() const;

  /// out = (A x)_e, the rows of element e (bs values).
  void rowProduct(int e, const double* x, double* out) const {
    std::fill(out, out + bs, 0.0);
    subtractRowProduct(e, x, out);
    for (int c = 0; c < bs; ++c) out[c] = -out[c];
  }

  /// out -= (A x)_e, the rows of element e (bs values). Compiled for the block sizes of the
  /// DG degrees and for the CPU's vector instructions (see block_rows.cpp).
  void subtractRowProduct(int e, const double* x, double* out) const;
};

extern template struct BlockRows<float>;
extern template struct BlockRows<double>;

/// The layout of a DG matrix's block rows, values allocated but unset: element e's slots
/// against neighbours[e] (sorted, e included), n functions per component; with
/// `componentDiagonal` (BZ) the slots between neighbours hold three n x n blocks.
BlockRows<double> blockRowsLayout(const std::vector<std::vector<std::uint32_t>>& neighbours, int n,
                                  bool componentDiagonal);

/// Writes element e's blocks into `rows` (blockRowsLayout(neighbours, ...)): its diagonal block
/// `self` (bs x bs, column-major), and its block against each neighbour f > e in order
/// (`coupling`, bs x bs each, row-major) into its row and, transposed, into f's. Every slot
/// has one writer, so elements can be written in parallel.
void writeElementRows(BlockRows<double>& rows,
                      const std::vector<std::vector<std::uint32_t>>& neighbours, std::size_t e,
                      const double* self, const double* coupling);

/// x += M s for a dense bs x bs column-major M (an element's inverse diagonal block in the
/// p-multigrid smoother or block-Jacobi), compiled like BlockRows::subtractRowProduct.
void addDenseProduct(int bs, const double* matrix, const double* s, double* x);

}  // namespace polydg
