// Compiling hot kernels for the CPU's vector instructions while the build targets the x86-64
// baseline: GCC function multiversioning compiles a kernel for AVX-512 (x86-64-v4), AVX2 with
// FMA (x86-64-v3) and the baseline (SSE2), and the loader picks the best the CPU has, so the
// binary runs anywhere.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define POLYDG_SIMD_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define POLYDG_SIMD_CLONES
#endif

/// Kernels inlined into each clone, so that each is compiled for the clone's instructions.
#define POLYDG_INLINE inline __attribute__((always_inline))
