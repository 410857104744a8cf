// The surface's hot loop, compiled for the CPU's vector instructions (util/simd_clones.h).
#pragma once

#include <cstddef>
#include <cstdint>

namespace polydg {

/// out[d] = sum over blocks k and functions i < n of w[k * n + i] u[(elements[k] * 3 + d) * n + i]:
/// a point's displacement from its weights by element blocks (SurfaceEmbedding::weightBlocks)
/// and the DG coefficients u.
void blockWeightedSum(int n, const std::uint32_t* elements, std::size_t blocks, const double* w,
                      const double* u, double out[3]);

}  // namespace polydg
