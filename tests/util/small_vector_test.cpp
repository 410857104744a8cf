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

TEST(SmallVector, AFacesCornersLeaveTheMembersInTheirPaddingAlone) {
  // Face::vertices lends the padding after its 16-bit counts to `loopEnd`: growing, copying,
  // moving and clearing it must leave each face's loop ends, `front`, `back` and `origin` as
  // they are.
  auto face = [](std::uint32_t end, std::size_t front, std::size_t back, FaceOrigin origin) {
    Face f;
    f.loopEnd = {end};
    f.front = ElementId(front);
    f.back = ElementId(back);
    f.origin = origin;
    return f;
  };
  auto ids = [](std::initializer_list<std::uint32_t> values) {
    SmallVector<VertexId, 4, std::uint16_t> out;
    for (std::uint32_t v : values) out.push_back(VertexId(std::size_t(v)));
    return out;
  };
  Face f = face(4, 7, 9, FaceOrigin::Cut), g = face(3, 5, 6, FaceOrigin::Surface);
  f.vertices = ids({1, 2, 3, 4});
  f.vertices.push_back(VertexId(std::size_t(5)));  // onto the heap
  g.vertices = ids({9, 8, 7});
  g.vertices = f.vertices;
  Face h = f;
  h.front = ElementId(std::size_t(3));
  h.loopEnd = {2};
  h.vertices = std::move(g.vertices);
  g.vertices = std::move(f.vertices);
  f.vertices.assign(2, VertexId(std::size_t(6)));
  g.vertices.swap(h.vertices);
  const std::array<std::array<std::uint32_t, 3>, 3> members{{{4, 7, 9}, {3, 5, 6}, {2, 3, 9}}};
  const std::array<FaceOrigin, 3> origins{FaceOrigin::Cut, FaceOrigin::Surface, FaceOrigin::Cut};
  const std::array<const Face*, 3> faces{&f, &g, &h};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(faces[i]->loopEnd, (LoopEnds{members[i][0]})) << "face " << i;
    EXPECT_EQ(faces[i]->front.value, members[i][1]) << "face " << i;
    EXPECT_EQ(faces[i]->back.value, members[i][2]) << "face " << i;
    EXPECT_EQ(faces[i]->origin, origins[i]) << "face " << i;
  }
  EXPECT_EQ(f.vertices, ids({6, 6}));
  EXPECT_EQ(g.vertices, ids({1, 2, 3, 4, 5}));
  EXPECT_EQ(h.vertices, ids({1, 2, 3, 4, 5}));
}

// What the mesh holds per face and per element (5.4 million faces and 1.6 million elements at
// the bunny's 200 cells): the inline room shares its place with the heap pointer.
static_assert(sizeof(SmallVector<VertexId, 4, std::uint16_t>) == 24);
static_assert(sizeof(Face) == 40);
static_assert(sizeof(Element) == 32);

}  // namespace
}  // namespace polydg
