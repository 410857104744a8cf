// A vector of trivially copyable values that keeps up to N of them inline, with 32-bit (or
// 16-bit) size and capacity after the inline values, which share their room with the heap
// pointer.
//
// Written here because Boost 1.74's small_vector (Debian 12) keeps a pointer, a 64-bit size and
// a 64-bit capacity beside the inline values (48 bytes for six 32-bit ids where this takes 32),
// and its options for a smaller size type came later. The mesh holds millions of faces and
// elements, each with one or two of these.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace polydg {

/// `Size` (std::uint32_t or std::uint16_t) bounds the number of values; growing beyond it throws
/// std::length_error. With 16-bit counts the last 4 bytes of the object are padding, which a
/// member declared [[no_unique_address]] leaves to the members after it.
template <class T, std::uint32_t N, class Size = std::uint32_t>
class SmallVector {
  static_assert(std::is_trivially_copyable_v<T>, "SmallVector holds trivially copyable values");
  static_assert(N > 0, "SmallVector keeps at least one value inline");
  static_assert(std::is_same_v<Size, std::uint32_t> || std::is_same_v<Size, std::uint16_t>);
  static_assert(N <= std::numeric_limits<Size>::max());

 public:
  using value_type = T;
  using size_type = std::size_t;
  using difference_type = std::ptrdiff_t;
  using reference = T&;
  using const_reference = const T&;
  using pointer = T*;
  using const_pointer = const T*;
  using iterator = T*;
  using const_iterator = const T*;
  using reverse_iterator = std::reverse_iterator<iterator>;
  using const_reverse_iterator = std::reverse_iterator<const_iterator>;

  SmallVector() noexcept {}
  explicit SmallVector(size_type n) { resize(n); }
  SmallVector(size_type n, const T& value) { assign(n, value); }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  SmallVector(It first, It last) {
    assign(first, last);
  }
  SmallVector(std::initializer_list<T> values) { assign(values.begin(), values.end()); }
  SmallVector(const SmallVector& other) { assign(other.begin(), other.end()); }
  SmallVector(SmallVector&& other) noexcept { take(other); }
  ~SmallVector() { release(); }

  SmallVector& operator=(const SmallVector& other) {
    if (this != &other) assign(other.begin(), other.end());
    return *this;
  }
  SmallVector& operator=(SmallVector&& other) noexcept {
    if (this != &other) {
      release();
      take(other);
    }
    return *this;
  }
  SmallVector& operator=(std::initializer_list<T> values) {
    assign(values.begin(), values.end());
    return *this;
  }

  // --- access ----------------------------------------------------------------------------
  size_type size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  size_type capacity() const noexcept { return capacity_; }
  T* data() noexcept { return onHeap() ? heap_ : inline_; }
  const T* data() const noexcept { return onHeap() ? heap_ : inline_; }
  iterator begin() noexcept { return data(); }
  iterator end() noexcept { return data() + size_; }
  const_iterator begin() const noexcept { return data(); }
  const_iterator end() const noexcept { return data() + size_; }
  const_iterator cbegin() const noexcept { return begin(); }
  const_iterator cend() const noexcept { return end(); }
  reverse_iterator rbegin() noexcept { return reverse_iterator(end()); }
  reverse_iterator rend() noexcept { return reverse_iterator(begin()); }
  const_reverse_iterator rbegin() const noexcept { return const_reverse_iterator(end()); }
  const_reverse_iterator rend() const noexcept { return const_reverse_iterator(begin()); }
  T& operator[](size_type i) noexcept { return data()[i]; }
  const T& operator[](size_type i) const noexcept { return data()[i]; }
  T& at(size_type i) {
    if (i >= size_) throw std::out_of_range("SmallVector::at");
    return data()[i];
  }
  const T& at(size_type i) const {
    if (i >= size_) throw std::out_of_range("SmallVector::at");
    return data()[i];
  }
  T& front() noexcept { return data()[0]; }
  const T& front() const noexcept { return data()[0]; }
  T& back() noexcept { return data()[size_ - 1]; }
  const T& back() const noexcept { return data()[size_ - 1]; }

  // --- changes ---------------------------------------------------------------------------
  void reserve(size_type n) {
    if (n > capacity_) grow(n);
  }
  void clear() noexcept { size_ = 0; }
  void resize(size_type n) { resize(n, T()); }
  void resize(size_type n, const T& value) {
    if (n > size_) {
      const T copy = value;  // `value` may be one of ours
      reserve(n);
      std::fill(data() + size_, data() + n, copy);
    }
    size_ = static_cast<Size>(n);
  }
  void assign(size_type n, const T& value) {
    const T copy = value;
    size_ = 0;
    resize(n, copy);
  }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  void assign(It first, It last) {
    clear();
    insert(end(), first, last);
  }
  void assign(std::initializer_list<T> values) { assign(values.begin(), values.end()); }

  void push_back(const T& value) {
    if (size_ == capacity_) {
      const T copy = value;  // `value` may be one of ours, and growing moves them
      grow(size_type(size_) + 1);
      data()[size_++] = copy;
      return;
    }
    data()[size_++] = value;
  }
  template <class... Args>
  T& emplace_back(Args&&... args) {
    push_back(T(std::forward<Args>(args)...));
    return back();
  }
  void pop_back() noexcept { --size_; }

  iterator insert(const_iterator pos, const T& value) { return insert(pos, size_type(1), value); }
  iterator insert(const_iterator pos, size_type n, const T& value) {
    const T copy = value;
    const size_type at = static_cast<size_type>(pos - begin());
    T* p = openGap(at, n);
    std::fill(p, p + n, copy);
    return p;
  }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  iterator insert(const_iterator pos, It first, It last) {
    const size_type at = static_cast<size_type>(pos - begin());
    const auto n = static_cast<size_type>(std::distance(first, last));
    if (n == 0) return begin() + at;
    if (aliases(first, last)) {  // a range of our own values: copy them out first
      const SmallVector copy(first, last);
      return insert(begin() + at, copy.begin(), copy.end());
    }
    T* p = openGap(at, n);
    std::copy(first, last, p);
    return p;
  }
  iterator insert(const_iterator pos, std::initializer_list<T> values) {
    return insert(pos, values.begin(), values.end());
  }
  template <class... Args>
  iterator emplace(const_iterator pos, Args&&... args) {
    return insert(pos, T(std::forward<Args>(args)...));
  }
  iterator erase(const_iterator pos) { return erase(pos, pos + 1); }
  iterator erase(const_iterator first, const_iterator last) {
    T* b = begin();
    const auto from = static_cast<size_type>(first - b), to = static_cast<size_type>(last - b);
    if (from != to) {
      std::memmove(static_cast<void*>(b + from), b + to, (size_ - to) * sizeof(T));
      size_ -= static_cast<Size>(to - from);
    }
    return b + from;
  }
  void swap(SmallVector& other) noexcept {
    SmallVector t(std::move(other));
    other = std::move(*this);
    *this = std::move(t);
  }

  friend bool operator==(const SmallVector& a, const SmallVector& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
  }
  friend bool operator!=(const SmallVector& a, const SmallVector& b) { return !(a == b); }

 private:
  bool onHeap() const noexcept { return capacity_ > N; }

  /// Makes room for n values at `at` (moving the later ones up) and returns where they go.
  T* openGap(size_type at, size_type n) {
    reserve(size_type(size_) + n);
    T* b = data();
    std::memmove(static_cast<void*>(b + at + n), b + at, (size_ - at) * sizeof(T));
    size_ += static_cast<Size>(n);
    return b + at;
  }

  template <class It>
  bool aliases(It first, It last) const {
    if constexpr (std::is_pointer_v<It>) {
      const T* b = data();
      const T* f = first;
      return last > first && f >= b && f < b + capacity_;
    } else {
      return false;
    }
  }

  void grow(size_type needed) {
    constexpr size_type kMost = std::numeric_limits<Size>::max();
    if (needed > kMost)
      throw std::length_error("SmallVector: more than " + std::to_string(kMost) + " values");
    const size_type capacity =
        std::min<size_type>(kMost, std::max<size_type>(needed, 2 * size_type(capacity_)));
    T* fresh = static_cast<T*>(::operator new(capacity * sizeof(T)));
    std::memcpy(static_cast<void*>(fresh), data(), size_ * sizeof(T));
    release();
    heap_ = fresh;
    capacity_ = static_cast<Size>(capacity);
  }

  void release() noexcept {
    if (onHeap()) ::operator delete(heap_);
    capacity_ = N;
  }

  /// Takes other's values; other is left empty and inline.
  void take(SmallVector& other) noexcept {
    size_ = other.size_;
    capacity_ = other.capacity_;
    if (other.onHeap())
      heap_ = other.heap_;
    else
      std::memcpy(static_cast<void*>(inline_), other.inline_, size_ * sizeof(T));
    other.size_ = 0;
    other.capacity_ = N;
  }

  union {
    T inline_[N];
    T* heap_;
  };
  Size size_ = 0;
  Size capacity_ = N;
};

}  // namespace polydg
