// Process-wide settings polydg's front ends apply once at start (the `polydg` binary in main(),
// the Python module when it is imported).
#pragma once

#if defined(__GLIBC__) || __has_include(<malloc.h>)
#include <malloc.h>
#endif

namespace polydg {

/// Keeps freed memory in the process for reuse instead of returning it to the kernel:
/// polydg allocates and frees large arrays again and again (a stiffness matrix per solve, per
/// pipeline input, per cut's region check), and memory fresh from the kernel must first be
/// faulted in and zeroed, about 0.15 ms per MB, more than an assembly of it takes. The price:
/// the process keeps
/// its peak footprint until it exits (glibc only; elsewhere the default policy stays).
inline void keepFreedMemory() {
#ifdef M_MMAP_THRESHOLD
  mallopt(M_MMAP_THRESHOLD, 1 << 30);  // blocks up to 1 GiB from the heap, not fresh mmaps
  mallopt(M_TRIM_THRESHOLD, 1 << 30);  // and keep up to 1 GiB of free heap
#endif
}

}  // namespace polydg
