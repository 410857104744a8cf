#include "physics/dynamics/corotation_kernels.h"

#include "util/simd_clones.h"

namespace polydg {

namespace {

/// N functions per component (0: n, known at run time only); compile-time sizes for the DG
/// degrees let the short loops unroll and vectorize.
template <int N>
POLYDG_INLINE void addWarpedOf(int n, const double* r, const double* b, double s, double* out) {
  const int nn = N > 0 ? N : n, bs = 3 * nn;
  constexpr int kMax = N > 0 ? 9 * N * N : 3600;  // degree 3 (n = 20) at most
  double t[kMax];                                 // T = (R (x) I) B, column-major
  for (int col = 0; col < bs; ++col) {
    const double* bc = b + col * bs;
    double* tc = t + col * bs;
    for (int d = 0; d < 3; ++d)
      for (int a = 0; a < nn; ++a)
        tc[d * nn + a] = r[d] * bc[a] + r[3 + d] * bc[nn + a] + r[6 + d] * bc[2 * nn + a];
  }
  // Column (c, j) of T (R (x) I)^T is sum_k R(c, k) times T's column (k, j).
  for (int c = 0; c < 3; ++c) {
    const double r0 = s * r[c], r1 = s * r[3 + c], r2 = s * r[6 + c];
    for (int j = 0; j < nn; ++j) {
      double* oc = out + (c * nn + j) * bs;
      const double* t0 = t + j * bs;
      const double* t1 = t + (nn + j) * bs;
      const double* t2 = t + (2 * nn + j) * bs;
      for (int row = 0; row < bs; ++row) oc[row] += r0 * t0[row] + r1 * t1[row] + r2 * t2[row];
    }
  }
}

template <int N>
POLYDG_INLINE void blockTimesOf(int n, const double* b, bool columnMajor, const double* w,
                                double* y) {
  const int bs = 3 * (N > 0 ? N : n);
  if (columnMajor) {  // column by column: no reduction in the inner loop, which vectorizes
    for (int i = 0; i < bs; ++i) y[i] = 0.0;
    for (int j = 0; j < bs; ++j) {
      const double* bc = b + j * bs;
      const double wj = w[j];
      for (int i = 0; i < bs; ++i) y[i] += bc[i] * wj;
    }
    return;
  }
  for (int i = 0; i < bs; ++i) {
    const double* bi = b + i * bs;
    double sum = 0.0;
    for (int j = 0; j < bs; ++j) sum += bi[j] * w[j];
    y[i] = sum;
  }
}

}  // namespace

POLYDG_SIMD_CLONES void addWarpedBlock(int n, const double* r, const double* b, double s,
                                       double* out) {
  switch (n) {
    case 4: return addWarpedOf<4>(n, r, b, s, out);
    case 10: return addWarpedOf<10>(n, r, b, s, out);
    case 20: return addWarpedOf<20>(n, r, b, s, out);
    default: return addWarpedOf<0>(n, r, b, s, out);
  }
}

POLYDG_SIMD_CLONES void blockTimes(int n, const double* b, bool columnMajor, const double* w,
                                   double* y) {
  switch (n) {
    case 4: return blockTimesOf<4>(n, b, columnMajor, w, y);
    case 10: return blockTimesOf<10>(n, b, columnMajor, w, y);
    case 20: return blockTimesOf<20>(n, b, columnMajor, w, y);
    default: return blockTimesOf<0>(n, b, columnMajor, w, y);
  }
}

}  // namespace polydg
