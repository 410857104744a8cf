// util/held_memory.h, in a process whose allocator is jemalloc (this test links it, as the
// polydg program does): freed memory is held until released, and released only when there is
// enough of it and the work that follows cannot reuse it.
#include "util/held_memory.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

namespace polydg {
namespace {

/// Allocates `bytes` in blocks of 4 KiB, writes them, and frees them.
void allocateAndFree(std::size_t bytes) {
  std::vector<std::unique_ptr<char[]>> blocks;
  for (std::size_t done = 0; done < bytes; done += 4096) {
    blocks.push_back(std::make_unique<char[]>(4096));
    blocks.back()[0] = 1;
  }
}

TEST(HeldMemory, FreedSmallBlocksAreHeldUntilReleased) {
  ASSERT_NE(mallctl, nullptr) << "this test must run with jemalloc as its allocator";
  releaseFreedMemory();
  const std::size_t before = heldFreedMemory();
  allocateAndFree(2 * kReleaseAtLeast);
  const std::size_t held = heldFreedMemory();
  EXPECT_GE(held, before + kReleaseAtLeast);
  EXPECT_TRUE(releaseFreedMemory());
  EXPECT_LT(heldFreedMemory(), kReleaseAtLeast / 16);
}

TEST(HeldMemory, LittleFreedMemoryIsKept) {
  ASSERT_NE(mallctl, nullptr) << "this test must run with jemalloc as its allocator";
  releaseFreedMemory();
  allocateAndFree(kReleaseAtLeast / 4);
  const std::size_t held = heldFreedMemory();
  EXPECT_GE(held, kReleaseAtLeast / 8);
  EXPECT_LT(held, kReleaseAtLeast);
  EXPECT_FALSE(releaseFreedMemory());
  EXPECT_EQ(heldFreedMemory(), held);
}

TEST(HeldMemory, FreedMemoryIsKeptForWorkWhoseArraysItCanServe) {
  ASSERT_NE(mallctl, nullptr) << "this test must run with jemalloc as its allocator";
  const std::size_t threshold = oversizeThreshold();
  ASSERT_GT(threshold, 0u);  // jemalloc's default is 8 MiB
  releaseFreedMemory();
  allocateAndFree(2 * kReleaseAtLeast);
  const std::size_t held = heldFreedMemory();
  // Arrays of a double per item just under the threshold: kept for them.
  EXPECT_FALSE(releaseFreedMemoryBefore(threshold / sizeof(double) - 1, sizeof(double)));
  EXPECT_EQ(heldFreedMemory(), held);
  // At the threshold they come from the oversize arena: returned.
  EXPECT_TRUE(releaseFreedMemoryBefore(threshold / sizeof(double), sizeof(double)));
  EXPECT_LT(heldFreedMemory(), kReleaseAtLeast / 16);
}

}  // namespace
}  // namespace polydg
