// Where each loop of a face ends (Face::loopEnd) in 8 bytes: a face with one loop, nearly every
// face, keeps its one end inline; a face with holes keeps its ends on the heap.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <new>
#include <stdexcept>

namespace polydg {

/// A list of 32-bit loop ends, at most one inline. The 8 bytes are two words: inline, the first
/// is the size (0 or 1) shifted left with its low bit set and the second the value; otherwise
/// they hold a pointer to a heap block (whose low bit, like any block's, is clear). 2^32 - 1
/// ends at most.
class LoopEnds {
  static_assert(std::endian::native == std::endian::little,
                "the inline mark is the low bit of the pointer's first word");

 public:
  using value_type = std::uint32_t;
  using size_type = std::size_t;
  using const_iterator = const std::uint32_t*;
  using iterator = std::uint32_t*;

  LoopEnds() noexcept { setInline(0, 0); }
  LoopEnds(std::initializer_list<std::uint32_t> values) : LoopEnds() {
    assign(values.begin(), values.end());
  }
  LoopEnds(const LoopEnds& other) : LoopEnds() { assign(other.begin(), other.end()); }
  LoopEnds(LoopEnds&& other) noexcept : LoopEnds() { swap(other); }
  ~LoopEnds() { release(); }

  LoopEnds& operator=(const LoopEnds& other) {
    if (this != &other) assign(other.begin(), other.end());
    return *this;
  }
  LoopEnds& operator=(LoopEnds&& other) noexcept {
    if (this != &other) {
      clear();
      swap(other);
    }
    return *this;
  }
  LoopEnds& operator=(std::initializer_list<std::uint32_t> values) {
    assign(values.begin(), values.end());
    return *this;
  }

  std::size_t size() const { return isInline() ? words_[0] >> 1 : heap()->size; }
  bool empty() const { return size() == 0; }
  const std::uint32_t* data() const { return isInline() ? &words_[1] : heap()->values(); }
  std::uint32_t* data() { return isInline() ? &words_[1] : heap()->values(); }
  const_iterator begin() const { return data(); }
  const_iterator end() const { return data() + size(); }
  iterator begin() { return data(); }
  iterator end() { return data() + size(); }
  std::uint32_t operator[](std::size_t i) const { return data()[i]; }
  std::uint32_t& operator[](std::size_t i) { return data()[i]; }

  void clear() {
    release();
    setInline(0, 0);
  }
  void push_back(std::uint32_t value) {
    const std::size_t n = size();
    if (isInline() && n == 0) {
      setInline(1, value);
      return;
    }
    reserve(n + 1);
    Heap* h = heap();
    h->values()[n] = value;
    h->size = static_cast<std::uint32_t>(n + 1);
  }
  /// The values [first, last), which must not be this list's own (as for std::vector).
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  void assign(It first, It last) {
    const auto n = static_cast<std::size_t>(std::distance(first, last));
    if (n <= 1) {  // at most one end is always inline, leaving the heap if it was there
      const std::uint32_t value = n == 1 ? static_cast<std::uint32_t>(*first) : 0;
      release();
      setInline(n, value);
      return;
    }
    LoopEnds copy;
    copy.reserve(n);
    std::copy(first, last, copy.heap()->values());
    copy.heap()->size = static_cast<std::uint32_t>(n);
    swap(copy);
  }
  void assign(std::size_t n, std::uint32_t value) {
    LoopEnds copy;
    for (std::size_t i = 0; i < n; ++i) copy.push_back(value);
    swap(copy);
  }
  void swap(LoopEnds& other) noexcept {
    std::uint32_t t[2];
    std::memcpy(t, words_, sizeof t);
    std::memcpy(words_, other.words_, sizeof t);
    std::memcpy(other.words_, t, sizeof t);
  }

  friend bool operator==(const LoopEnds& a, const LoopEnds& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end());
  }

 private:
  struct Heap {
    std::uint32_t size, capacity;
    std::uint32_t* values() { return reinterpret_cast<std::uint32_t*>(this + 1); }
  };
  static_assert(alignof(Heap) == alignof(std::uint32_t));

  bool isInline() const { return words_[0] & 1u; }
  void setInline(std::size_t n, std::uint32_t value) {
    words_[0] = static_cast<std::uint32_t>(n << 1 | 1u);
    words_[1] = value;
  }
  Heap* heap() const {
    Heap* h;
    std::memcpy(&h, words_, sizeof h);
    return h;
  }
  void release() {
    if (!isInline()) ::operator delete(heap());
  }
  /// Room for n ends on the heap, keeping the ends there are.
  void reserve(std::size_t n) {
    if (!isInline() && heap()->capacity >= n) return;
    if (n > std::numeric_limits<std::uint32_t>::max())
      throw std::length_error("LoopEnds: more than 2^32 - 1 loops");
    const std::size_t have = size();
    const std::size_t capacity = std::max<std::size_t>(n, 2 * have);
    auto* h = static_cast<Heap*>(::operator new(sizeof(Heap) + capacity * sizeof(std::uint32_t)));
    h->size = static_cast<std::uint32_t>(have);
    h->capacity = static_cast<std::uint32_t>(capacity);
    std::copy(begin(), end(), h->values());
    release();
    std::memcpy(words_, &h, sizeof h);
  }

  std::uint32_t words_[2];
};
static_assert(sizeof(LoopEnds) == 8);
static_assert(sizeof(void*) == 8, "a heap block's pointer fills the two words");

}  // namespace polydg
