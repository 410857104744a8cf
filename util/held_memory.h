// Freed memory the allocator holds. jemalloc, the polydg program's allocator
// (cli/allocator.cpp), keeps freed pages for reuse for seconds. After slicing, what it holds is
// the small allocations of the splitting and the build, which the large arrays that follow (the
// mesh's, validation's, the writer's: jemalloc serves allocations of 8 MB and more from an arena
// of their own) cannot reuse: held, they only raise the peak. Smaller arrays can, and for those
// the memory is kept (releaseFreedMemoryBefore).
#pragma once

#include <cstddef>
#include <cstdint>

// jemalloc's control interface, if jemalloc is the process's allocator (weak: null otherwise).
extern "C" int mallctl(const char* name, void* oldp, std::size_t* oldlenp, void* newp,
                       std::size_t newlen) __attribute__((weak));

namespace polydg {

/// Freed memory worth returning to the kernel: less is reused sooner than its return saves
/// (pages returned are faulted in and zeroed again when reused).
inline constexpr std::size_t kReleaseAtLeast = std::size_t(32) << 20;

/// The freed memory jemalloc holds in all its arenas, in bytes; 0 without jemalloc.
inline std::size_t heldFreedMemory() {
  if (!mallctl) return 0;
  std::uint64_t epoch = 1;  // refreshes the statistics read below
  std::size_t size = sizeof(epoch);
  if (mallctl("epoch", &epoch, &size, &epoch, size) != 0) return 0;
  std::size_t pages = 0, page = 0;
  size = sizeof(pages);
  if (mallctl("stats.arenas.4096.pdirty", &pages, &size, nullptr, 0) != 0) return 0;
  size = sizeof(page);
  if (mallctl("arenas.page", &page, &size, nullptr, 0) != 0) return 0;
  return pages * page;
}

/// Returns the freed memory jemalloc holds to the kernel if it is at least kReleaseAtLeast;
/// returns whether it did. Nothing without jemalloc (the Python module's glibc malloc keeps
/// freed memory, polydg/util/process.h).
inline bool releaseFreedMemory() {
  if (heldFreedMemory() < kReleaseAtLeast) return false;
  return mallctl("arena.4096.purge", nullptr, nullptr, nullptr, 0) == 0;
}

/// jemalloc's oversize threshold: allocations of at least this many bytes come from an arena of
/// their own, which reuses none of the memory freed in the others; 0 without jemalloc.
inline std::size_t oversizeThreshold() {
  if (!mallctl) return 0;
  std::size_t threshold = 0, size = sizeof(threshold);
  if (mallctl("opt.oversize_threshold", &threshold, &size, nullptr, 0) != 0) return 0;
  return threshold;
}

/// releaseFreedMemory() before work whose arrays hold `perItem` bytes for each of `items`: if
/// such an array stays under the oversize threshold, the work's arrays are served from the
/// memory held, which is then kept (returned, it would be faulted in and zeroed again).
inline bool releaseFreedMemoryBefore(std::size_t items, std::size_t perItem) {
  if (items * perItem < oversizeThreshold()) return false;
  return releaseFreedMemory();
}

}  // namespace polydg
