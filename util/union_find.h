// A disjoint-set forest (union-find) over the indices 0 .. n-1: the one way polydg groups
// triangles, polygons, faces and elements into connected components.
#pragma once

#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

namespace polydg {

/// Sets of the indices 0 .. n-1, joined by unite(); find() with path halving.
class UnionFind {
 public:
  explicit UnionFind(std::size_t n = 0) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), std::uint32_t(0));
  }

  std::size_t size() const { return parent_.size(); }

  /// Adds the index size(), a set of its own, and returns it.
  std::uint32_t add() {
    const auto i = static_cast<std::uint32_t>(parent_.size());
    parent_.push_back(i);
    return i;
  }

  /// The representative of i's set.
  std::uint32_t find(std::uint32_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }

  /// Joins the sets of a and b; the representative of b's set represents the union.
  void unite(std::uint32_t a, std::uint32_t b) { parent_[find(a)] = find(b); }

  /// The number of sets: of roots, the indices that are their own parent.
  std::size_t count() const {
    std::size_t roots = 0;
    for (std::uint32_t i = 0; i < parent_.size(); ++i) roots += parent_[i] == i;
    return roots;
  }

  /// Every index's representative, in a vector taken from the forest, which is left empty: for
  /// a caller that relabels the sets in that storage instead of allocating another array.
  std::vector<std::uint32_t> takeRepresentatives() {
    for (std::uint32_t i = 0; i < parent_.size(); ++i) parent_[i] = find(i);
    return std::move(parent_);
  }

  /// One label per index, 0 .. count-1, numbering the sets in order of their smallest index;
  /// returns the number of sets.
  std::size_t labels(std::vector<std::uint32_t>& out) {
    constexpr std::uint32_t kNone = ~std::uint32_t(0);
    std::vector<std::uint32_t> labelOfRoot(parent_.size(), kNone);
    out.resize(parent_.size());
    std::uint32_t count = 0;
    for (std::uint32_t i = 0; i < parent_.size(); ++i) {
      std::uint32_t& label = labelOfRoot[find(i)];
      if (label == kNone) label = count++;
      out[i] = label;
    }
    return count;
  }

 private:
  std::vector<std::uint32_t> parent_;
};

}  // namespace polydg
