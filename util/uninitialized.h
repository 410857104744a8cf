// Arrays of numbers that are filled right after they are made, in parallel: no serial zeroing
// pass first, and each page first touched by the thread that fills it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "util/resident.h"

namespace polydg {

/// An allocator whose value-less construct() default-initializes: resize() of a vector of
/// numbers leaves them unset, where std::allocator zeroes them in one serial pass. For arrays
/// that are filled right after, in parallel (at 1.3 million DOFs the zeroing of the block rows
/// was a serial pass over 1.3 GB).
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  /// Huge pages for a large array (the block rows of K and of its coarse levels, read in every
  /// product): adviseLargeBlock. The polydg program's operator new does so for every block
  /// (cli/allocator.cpp); this is for the library's other hosts, the Python module's.
  T* allocate(std::size_t n) {
    T* p = std::allocator<T>::allocate(n);
    adviseLargeBlock(p, n * sizeof(T));
    return p;
  }
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

/// A vector of numbers left unset by resize().
template <class T>
using UninitializedVector = std::vector<T, UninitializedAllocator<T>>;

/// `v` resized to `size` and zeroed in parallel.
template <class T>
void assignZeros(UninitializedVector<T>& v, std::size_t size) {
  v.resize(size);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, size, 1 << 16),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      std::fill(v.begin() + static_cast<std::ptrdiff_t>(r.begin()),
                                v.begin() + static_cast<std::ptrdiff_t>(r.end()), T(0));
                    });
}

}  // namespace polydg
