// SmallVector (polydg/util/small_vector.h) against std::vector: the same values after the same
// operations, inline and on the heap, including inserting a vector's own values into itself.
#include "polydg/util/small_vector.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {
namespace {

using Small = SmallVector<std::uint32_t, 3>;

void expectSame(const Small& s, const std::vector<std::uint32_t>& v, int step) {
  ASSERT_EQ(s.size(), v.size()) << "after step " << step;
  ASSERT_GE(s.capacity(), s.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    ASSERT_EQ(s[i], v[i]) << "value " << i << ", step " << step;
}

TEST(SmallVector, DoesWhatStdVectorDoesOverRandomOperations) {
  std::mt19937 random(20261205);  // a fixed sequence
  Small s;
  std::vector<std::uint32_t> v;
  for (int step = 0; step < 20000; ++step) {
    const auto value = static_cast<std::uint32_t>(random());
    const std::size_t at = v.empty() ? 0 : random() % (v.size() + 1);
    switch (random() % 11) {
      case 0:
      case 1:
        s.push_back(value);
        v.push_back(value);
        break;
      case 2:
        s.insert(s.begin() + at, value);
        v.insert(v.begin() + at, value);
        break;
      case 3:
        if (!v.empty() && at < v.size()) {
          s.erase(s.begin() + at);
          v.erase(v.begin() + at);
        }
        break;
      case 4: {  // a range of its own values, at any place: the values before the insertion
        const std::size_t from = at / 2, to = at;
        const std::vector<std::uint32_t> part(v.begin() + from, v.begin() + to);
        s.insert(s.begin() + at / 3, s.begin() + from, s.begin() + to);
        v.insert(v.begin() + at / 3, part.begin(), part.end());
        break;
      }
      case 5: {
        const std::size_t n = value % 9;
        s.resize(n, value);
        v.resize(n, value);
        break;
      }
      case 6:
        if (!v.empty()) {
          s.push_back(s.front());  // a value of its own, when growing moves them
          v.push_back(v.front());
        }
        break;
      case 7: {
        const std::size_t to = std::min(v.size(), at + value % 4);
        s.erase(s.begin() + at, s.begin() + to);
        v.erase(v.begin() + at, v.begin() + to);
        break;
      }
      case 8: {  // copies and moves, inline or not
        Small copy(s);
        Small moved(std::move(copy));
        EXPECT_TRUE(copy.empty());
        s = moved;
        break;
      }
      case 9:
        if (value % 50 == 0) {
          s.clear();
          v.clear();
        }
        break;
      default: {
        const std::uint32_t values[] = {value, value + 1, value + 2, value + 3};
        s.assign(values, values + value % 5);
        v.assign(values, values + value % 5);
      }
    }
    expectSame(s, v, step);
  }
}

TEST(SmallVector, MovesLeaveTheSourceEmptyAndSwapExchanges) {
  Small inlined{1, 2}, heap{1, 2, 3, 4, 5};
  EXPECT_EQ(inlined.capacity(), 3u);
  EXPECT_GT(heap.capacity(), 3u);
  Small a(std::move(heap));
  EXPECT_TRUE(heap.empty());
  EXPECT_EQ(heap.capacity(), 3u);
  EXPECT_EQ(a, (Small{1, 2, 3, 4, 5}));
  a.swap(inlined);
  EXPECT_EQ(a, (Small{1, 2}));
  EXPECT_EQ(inlined, (Small{1, 2, 3, 4, 5}));
  a = std::move(inlined);
  EXPECT_EQ(a, (Small{1, 2, 3, 4, 5}));
  EXPECT_NE(a, (Small{1, 2, 3, 4, 6}));
}

TEST(SmallVector, SixteenBitCountsStopAtTheirLargest) {
  SmallVector<std::uint32_t, 2, std::uint16_t> v;
  v.resize(65535, 3);
  EXPECT_EQ(v.size(), 65535u);
  EXPECT_EQ(v.back(), 3u);
  EXPECT_THROW(v.push_back(1), std::length_error);
  EXPECT_THROW(v.insert(v.begin(), 2, 1), std::length_error);
  EXPECT_EQ(v.size(), 65535u);
}

TEST(SmallVector, AFacesLoopEndsLeaveTheMembersInTheirPaddingAlone) {
  // Face::loopEnd lends the padding after its 16-bit counts to `front`: growing, copying,
  // moving and clearing it must leave each face's `front`, `back` and `origin` as they are.
  auto face = [](std::size_t front, std::size_t back, FaceOrigin origin) {
    Face f;
    f.front = ElementId(front);
    f.back = ElementId(back);
    f.origin = origin;
    return f;
  };
  Face f = face(7, 9, FaceOrigin::Cut), g = face(5, 6, FaceOrigin::Surface);
  f.loopEnd = {4, 8};
  f.loopEnd.push_back(12);  // onto the heap
  g.loopEnd = {3};
  g.loopEnd = f.loopEnd;
  Face h = f;
  h.front = ElementId(std::size_t(3));
  h.loopEnd = std::move(g.loopEnd);
  g.loopEnd = std::move(f.loopEnd);
  f.loopEnd.assign(1, 4);
  g.loopEnd.swap(h.loopEnd);
  const std::array<std::array<std::uint32_t, 2>, 3> links{{{7, 9}, {5, 6}, {3, 9}}};
  const std::array<FaceOrigin, 3> origins{FaceOrigin::Cut, FaceOrigin::Surface, FaceOrigin::Cut};
  const std::array<const Face*, 3> faces{&f, &g, &h};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(faces[i]->front.value, links[i][0]) << "face " << i;
    EXPECT_EQ(faces[i]->back.value, links[i][1]) << "face " << i;
    EXPECT_EQ(faces[i]->origin, origins[i]) << "face " << i;
  }
  using LoopEnds = SmallVector<std::uint32_t, 2, std::uint16_t>;
  EXPECT_EQ(f.loopEnd, (LoopEnds{4}));
  EXPECT_EQ(g.loopEnd, (LoopEnds{4, 8, 12}));
  EXPECT_EQ(h.loopEnd, (LoopEnds{4, 8, 12}));
}

// What the mesh holds per face and per element (5.4 million faces and 1.6 million elements at
// the bunny's 200 cells): the inline room shares its place with the heap pointer.
static_assert(sizeof(SmallVector<VertexId, 4>) == 24);
static_assert(sizeof(Face) == 48);
static_assert(sizeof(Element) == 32);

}  // namespace
}  // namespace polydg
