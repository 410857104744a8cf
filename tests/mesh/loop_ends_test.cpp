// A face's loop ends in 8 bytes: none or one inline, more on the heap, through every way a list
// is filled, copied, moved and emptied.
#include "polydg/mesh/loop_ends.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace polydg {
namespace {

std::vector<std::uint32_t> values(const LoopEnds& ends) { return {ends.begin(), ends.end()}; }

/// Whether the list's values live inside the object (inline) rather than on the heap.
bool isInline(const LoopEnds& ends) {
  const auto* self = reinterpret_cast<const char*>(&ends);
  const auto* data = reinterpret_cast<const char*>(ends.data());
  return data >= self && data < self + sizeof ends;
}

TEST(LoopEnds, OneEndIsInlineAndMoreGoToTheHeap) {
  LoopEnds ends;
  EXPECT_TRUE(ends.empty());
  EXPECT_EQ(ends.size(), 0u);
  EXPECT_TRUE(isInline(ends));
  ends.push_back(7);
  EXPECT_EQ(values(ends), (std::vector<std::uint32_t>{7}));
  EXPECT_TRUE(isInline(ends));
  for (std::uint32_t v = 8; v < 40; ++v) ends.push_back(v);
  ASSERT_EQ(ends.size(), 33u);
  EXPECT_FALSE(isInline(ends));
  for (std::size_t i = 0; i < ends.size(); ++i) EXPECT_EQ(ends[i], 7 + i);
  ends[3] = 100;
  EXPECT_EQ(ends[3], 100u);
  // Assigning one end, or none, comes back inline; the largest value stays whole.
  const std::uint32_t largest = std::numeric_limits<std::uint32_t>::max();
  ends.assign(1, largest);
  EXPECT_EQ(values(ends), (std::vector<std::uint32_t>{largest}));
  EXPECT_TRUE(isInline(ends));
  ends = {3, 9};
  EXPECT_FALSE(isInline(ends));
  ends.clear();
  EXPECT_TRUE(ends.empty());
  EXPECT_TRUE(isInline(ends));
}

TEST(LoopEnds, CopiesMovesSwapsAndSelfAssignmentKeepTheValues) {
  const LoopEnds one{4}, three{4, 8, 12};
  LoopEnds a = three, b = one;
  EXPECT_EQ(a, three);
  EXPECT_EQ(b, one);
  EXPECT_FALSE(a == b);
  a.swap(b);
  EXPECT_EQ(a, one);
  EXPECT_EQ(b, three);
  LoopEnds c = std::move(b);
  EXPECT_EQ(c, three);
  EXPECT_TRUE(b.empty());  // NOLINT(bugprone-use-after-move): a moved-from list is empty
  b = c;
  c = std::move(a);
  EXPECT_EQ(b, three);
  EXPECT_EQ(c, one);
  // Shrinking from the heap to one end comes back inline.
  b.assign(three.begin() + 2, three.end());
  EXPECT_EQ(values(b), (std::vector<std::uint32_t>{12}));
  EXPECT_TRUE(isInline(b));
  const LoopEnds& same = b;
  b = same;
  EXPECT_EQ(values(b), (std::vector<std::uint32_t>{12}));
  const std::vector<std::uint32_t> many{1, 2, 3, 4, 5, 6};
  b.assign(many.begin(), many.end());
  EXPECT_EQ(values(b), many);
  b.assign(0, 5);
  EXPECT_TRUE(b.empty());
}

static_assert(sizeof(LoopEnds) == 8);

}  // namespace
}  // namespace polydg
