// Strongly typed indices for vertices, faces and elements, and containers of data attached to
// each, so that a face quantity can never be indexed by an element id by mistake.
#pragma once

#include <cassert>
#include <compare>
#include <cstdint>
#include <limits>
#include <vector>

namespace polydg {

/// A typed index. `Tag` only distinguishes the kinds; the value is a plain 32-bit index.
template <class Tag>
struct Id {
  static constexpr std::uint32_t kInvalid = std::numeric_limits<std::uint32_t>::max();

  std::uint32_t value = kInvalid;

  constexpr Id() = default;
  constexpr explicit Id(std::uint32_t v) : value(v) {}
  constexpr explicit Id(std::size_t v) : value(static_cast<std::uint32_t>(v)) {}
  constexpr explicit Id(int v) : value(static_cast<std::uint32_t>(v)) { assert(v >= 0); }

  constexpr bool valid() const { return value != kInvalid; }
  constexpr std::size_t index() const { return value; }
  constexpr auto operator<=>(const Id&) const = default;
};

struct VertexTag {};
struct FaceTag {};
struct ElementTag {};
using VertexId = Id<VertexTag>;
using FaceId = Id<FaceTag>;
using ElementId = Id<ElementTag>;

/// A vector indexed only by `Id<Tag>`.
template <class Tag, class T>
class IndexedData {
 public:
  IndexedData() = default;
  explicit IndexedData(std::size_t n, const T& value = T()) : data_(n, value) {}

  T& operator[](Id<Tag> id) { return data_[id.index()]; }
  const T& operator[](Id<Tag> id) const { return data_[id.index()]; }

  std::size_t size() const { return data_.size(); }
  void resize(std::size_t n) { data_.resize(n); }
  void resize(std::size_t n, const T& value) { data_.resize(n, value); }
  void push_back(const T& value) { data_.push_back(value); }
  auto begin() { return data_.begin(); }
  auto end() { return data_.end(); }
  auto begin() const { return data_.begin(); }
  auto end() const { return data_.end(); }
  /// The underlying storage, in index order.
  std::vector<T>& raw() { return data_; }
  const std::vector<T>& raw() const { return data_; }

 private:
  std::vector<T> data_;
};

template <class T>
using VertexData = IndexedData<VertexTag, T>;
template <class T>
using FaceData = IndexedData<FaceTag, T>;
template <class T>
using ElementData = IndexedData<ElementTag, T>;

}  // namespace polydg

template <class Tag>
struct std::hash<polydg::Id<Tag>> {
  std::size_t operator()(const polydg::Id<Tag>& id) const noexcept { return id.value; }
};
