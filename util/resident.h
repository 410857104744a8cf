// Large arrays whose pages are faulted in on all cores before they are filled. A page of fresh
// memory costs a fault and zeroing when it is first written; on a virtual machine that backs its
// memory lazily (this project's benchmark machine) that is 1-2 ms per MB, so one thread
// constructing a 500 MB array of faces spends about a second in page faults.
#pragma once

#include <sys/mman.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/parallel_for.h>

namespace polydg {

/// Asks the kernel for transparent huge pages on the 2 MiB-aligned part of [data, data +
/// bytes), a large array's: it then faults in 2 MiB at a time instead of 4 KiB, and its reads
/// miss the TLB less. (The polydg program's heap is on huge pages as a whole, cli/allocator.cpp;
/// the Python module's glibc heap is not.) A hint only; ignored where unsupported.
inline void adviseHugePages(void* data, std::size_t bytes) {
#ifdef MADV_HUGEPAGE
  constexpr std::uintptr_t kHuge = std::uintptr_t(1) << 21;
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

/// Blocks from this size on are advised onto huge pages (adviseLargeBlock): each holds at least
/// one whole one; smaller blocks are left to the heap's own pages.
inline constexpr std::size_t kHugePagesAtLeast = std::size_t(4) << 20;

/// adviseHugePages for a block of kHugePagesAtLeast bytes or more; nothing for a smaller one.
inline void adviseLargeBlock(void* data, std::size_t bytes) {
  if (bytes >= kHugePagesAtLeast) adviseHugePages(data, bytes);
}

/// Faults in the pages of [data, data + bytes) for writing, in parallel, without touching their
/// contents (Linux 5.14's MADV_POPULATE_WRITE). Does nothing for small ranges, or where the
/// kernel cannot: the pages then fault in when they are first written, as they would anyway.
inline void makeResident(void* data, std::size_t bytes) {
#ifdef MADV_POPULATE_WRITE
  // One huge page a task, from two on: the arrays of a few MB that checks and caches make
  // while the other core waits are faulted in on both too.
  constexpr std::uintptr_t kChunk = std::uintptr_t(2) << 20;
  if (bytes < 2 * kChunk) return;
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t end = begin + bytes;
  const std::uintptr_t first = (begin + kChunk - 1) / kChunk * kChunk;  // aligned chunks
  const std::size_t chunks = (end - first) / kChunk;
  adviseHugePages(data, bytes);
  tbb::parallel_for(std::size_t(0), chunks + 1, [&](std::size_t c) {
    // Chunk `chunks` is the unaligned rest at both ends: the head before `first` (whole pages
    // only) and the tail after the last aligned chunk.
    if (c < chunks) {
      ::madvise(reinterpret_cast<void*>(first + c * kChunk), kChunk, MADV_POPULATE_WRITE);
      return;
    }
    const std::uintptr_t page = 4096;
    const std::uintptr_t head = (begin + page - 1) / page * page;
    if (head < first) ::madvise(reinterpret_cast<void*>(head), first - head, MADV_POPULATE_WRITE);
    const std::uintptr_t tail = first + chunks * kChunk;
    const std::uintptr_t tailEnd = end / page * page;
    if (tail < tailEnd)
      ::madvise(reinterpret_cast<void*>(tail), tailEnd - tail, MADV_POPULATE_WRITE);
  });
#else
  (void)data;
  (void)bytes;
#endif
}

/// Resizes `v` to n, the pages of a growth made resident first (makeResident), so that the
/// constructing pass is a plain serial write; new elements are copies of `value`, or
/// value-initialized without it. Grows geometrically, as std::vector does.
template <class T, class... Value>
void growResident(std::vector<T>& v, std::size_t n, const Value&... value) {
  static_assert(sizeof...(Value) <= 1);
  if (n > v.capacity()) v.reserve(std::max(n, 2 * v.capacity()));
  if (n > v.size()) makeResident(v.data() + v.size(), (n - v.size()) * sizeof(T));
  v.resize(n, value...);
}

/// `size` value-initialized T in a vector whose pages were made resident first.
template <class T>
std::vector<T> residentVector(std::size_t size) {
  std::vector<T> v;
  growResident(v, size);
  return v;
}

}  // namespace polydg
