// The polydg program's memory allocator: jemalloc (linked into this executable only, not into the
// library or the Python module), its heap on transparent huge pages, in one arena.
//
// Meshing builds hundreds of MB of small, short-lived buffers (plane splits, faces, element
// lists) and solving allocates K and its preconditioner once, large. With glibc's malloc on
// 4 KiB pages, `polydg mesh` of a 75k-triangle scan at 64 cells spent about a third of its wall
// time in page faults; jemalloc reuses the small buffers' pages. A fault costs about 9 us on
// this kind of virtual machine, so the heap faults in 2 MiB at a time ("thp:always"): the bunny
// meshed at 64 cells in 0.87 of the time, at 200 cells in 0.93, a solve and a simulation in
// 0.90 (docs/benchmarks.md, "The heap on huge pages, in one arena"). Its cost is every partly
// used 2 MiB page counted in full; one arena ("narenas:1", where jemalloc makes four per CPU)
// keeps those few: 10-20 MiB more at the peak, where eight arenas cost up to 37. Every block of
// 4 MiB or more is also advised onto huge pages below (operator new; makeResident in
// util/resident.h also faults a large array in on all cores), which still holds when a user's
// MALLOC_CONF takes the heap off them.
// jemalloc reads this string when it starts (before main), then /etc/malloc.conf, then the
// environment variable MALLOC_CONF, each overriding the one before: a user who wants other
// settings sets MALLOC_CONF.
#include <cstddef>
#include <cstdlib>
#include <new>

#include "util/resident.h"

extern "C" {
// NOLINTNEXTLINE(readability-identifier-naming): the name jemalloc looks for.
extern const char* malloc_conf;
const char* malloc_conf = "thp:always,narenas:1,metadata_thp:disabled";
}

namespace {

/// A large block is advised onto huge pages (adviseLargeBlock), so that it faults in 2 MiB at a
/// time instead of 4 KiB: a fault is dear on a virtual machine.
void* allocateOrNull(std::size_t n) noexcept {
  void* p = std::malloc(n == 0 ? 1 : n);
  if (p != nullptr) polydg::adviseLargeBlock(p, n);
  return p;
}

void* allocate(std::size_t n) {
  void* p = allocateOrNull(n);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

}  // namespace

// The replaceable allocation functions but the aligned ones (those keep the standard library's,
// over aligned_alloc and free): every other C++ allocation of the program comes here, the
// library's and the standard containers' included. Each form is replaced, since the standard
// library's own forms need not call the replaced ones.
void* operator new(std::size_t n) { return allocate(n); }
void* operator new[](std::size_t n) { return allocate(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return allocateOrNull(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return allocateOrNull(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
