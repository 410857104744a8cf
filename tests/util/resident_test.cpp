// util/resident.h: making pages resident changes no byte, at any alignment, and a resident
// vector holds value-initialized elements.
#include "util/resident.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {
namespace {

std::uint8_t pattern(std::size_t i) { return static_cast<std::uint8_t>(i * 2654435761u >> 13); }

TEST(Resident, MakingPagesResidentKeepsEveryByte) {
  // 24 MB, several aligned 2 MB chunks, with the range starting and ending inside pages.
  std::vector<std::uint8_t> bytes(24u << 20);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = pattern(i);
  for (const std::size_t skip :
       {std::size_t(0), std::size_t(1), std::size_t(4095), std::size_t(12345)}) {
    makeResident(bytes.data() + skip, bytes.size() - 2 * skip);
    std::size_t changed = 0;
    for (std::size_t i = 0; i < bytes.size(); ++i) changed += bytes[i] != pattern(i);
    EXPECT_EQ(changed, 0u) << "range starting " << skip << " bytes in";
  }
}

TEST(Resident, ResidentVectorHoldsValueInitializedElements) {
  const std::size_t n = (20u << 20) / sizeof(Face) + 3;  // above the size made resident
  std::vector<Face> faces = residentVector<Face>(n);
  ASSERT_EQ(faces.size(), n);
  std::size_t set = 0;
  for (const Face& f : faces)
    set += !f.vertices.empty() || !f.loopEnd.empty() || f.front.valid() || f.back.valid() ||
           f.origin != FaceOrigin::Interior;
  EXPECT_EQ(set, 0u);
  const std::vector<std::uint32_t> numbers = residentVector<std::uint32_t>(5u << 20);
  std::size_t nonzero = 0;
  for (std::uint32_t x : numbers) nonzero += x != 0;
  EXPECT_EQ(nonzero, 0u);
}

}  // namespace
}  // namespace polydg
