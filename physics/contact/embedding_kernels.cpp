#include "physics/contact/embedding_kernels.h"

#include "util/simd_clones.h"

namespace polydg {

namespace {

/// N functions an element (0: n, known at run time only): a block is N weights against N
/// coefficients of each component, summed lane by lane and the lanes added at the end.
template <int N>
POLYDG_INLINE void blockSumOf(int n, const std::uint32_t* elements, std::size_t blocks,
                              const double* w, const double* u, double out[3]) {
  constexpr int kLanes = N > 0 ? N : 20;  // degree 3 (n = 20) at most
  const int nn = N > 0 ? N : n;
  double x[kLanes] = {}, y[kLanes] = {}, z[kLanes] = {};
  for (std::size_t k = 0; k < blocks; ++k) {
    const double* wk = w + k * static_cast<std::size_t>(nn);
    const double* uk = u + static_cast<std::size_t>(elements[k]) * 3 * static_cast<std::size_t>(nn);
    for (int i = 0; i < nn; ++i) {
      x[i] += wk[i] * uk[i];
      y[i] += wk[i] * uk[nn + i];
      z[i] += wk[i] * uk[2 * nn + i];
    }
  }
  out[0] = out[1] = out[2] = 0.0;
  for (int i = 0; i < nn; ++i) {
    out[0] += x[i];
    out[1] += y[i];
    out[2] += z[i];
  }
}

}  // namespace

POLYDG_SIMD_CLONES void blockWeightedSum(int n, const std::uint32_t* elements, std::size_t blocks,
                                         const double* w, const double* u, double out[3]) {
  switch (n) {
    case 4: return blockSumOf<4>(n, elements, blocks, w, u, out);
    case 10: return blockSumOf<10>(n, elements, blocks, w, u, out);
    case 20: return blockSumOf<20>(n, elements, blocks, w, u, out);
    default: return blockSumOf<0>(n, elements, blocks, w, u, out);
  }
}

}  // namespace polydg
