// cli/allocator.cpp: the polydg program's heap is on huge pages, small blocks and large, in one
// arena for all threads (read back from the kernel's /proc/self/smaps and from jemalloc).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "util/held_memory.h"
#include "util/resident.h"

namespace {

/// Whether the mapping that holds `address` is advised onto huge pages: "hg" in its VmFlags.
bool advisedOntoHugePages(const void* address) {
  const auto a = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= a && a < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line.find(" hg") != std::string::npos;
    }
  }
  ADD_FAILURE() << "no mapping in /proc/self/smaps holds " << address;
  return false;
}

/// The first 2 MiB boundary at or after `p`: where a huge page of its block would begin.
const void* firstHugePageIn(const void* p) {
  constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
  return reinterpret_cast<const void*>((reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) &
                                       ~(kHuge - 1));
}

TEST(Allocator, SmallAndLargeBlocksAreAdvisedOntoHugePages) {
  if (!std::filesystem::exists("/sys/kernel/mm/transparent_hugepage"))
    GTEST_SKIP() << "this kernel has no transparent huge pages";
  constexpr std::size_t kHuge = std::size_t(2) << 20;
  // The heap's own blocks (jemalloc's "thp:always"): a small object and a block of 64 KiB.
  const auto tiny = std::make_unique<char[]>(48);
  const auto small = std::make_unique<char[]>(std::size_t(64) << 10);
  EXPECT_TRUE(advisedOntoHugePages(tiny.get()));
  EXPECT_TRUE(advisedOntoHugePages(small.get()));
  // Large blocks, which operator new also advises itself (for a MALLOC_CONF without them).
  const auto large = std::make_unique<char[]>(std::size_t(16) << 20);
  EXPECT_TRUE(advisedOntoHugePages(firstHugePageIn(large.get())));
  EXPECT_TRUE(advisedOntoHugePages(large.get() + (std::size_t(16) << 20) - kHuge - 1));
  const std::vector<char> containers(std::size_t(12) << 20);  // through std::allocator
  EXPECT_TRUE(advisedOntoHugePages(firstHugePageIn(containers.data())));
  const auto nothrowLarge = std::unique_ptr<char[]>(new (std::nothrow) char[std::size_t(8) << 20]);
  ASSERT_NE(nothrowLarge, nullptr);
  EXPECT_TRUE(advisedOntoHugePages(firstHugePageIn(nothrowLarge.get())));
}

/// The arena jemalloc serves the calling thread's allocations from.
unsigned threadArena() {
  unsigned arena = 0;
  std::size_t size = sizeof(arena);
  EXPECT_EQ(mallctl("thread.arena", &arena, &size, nullptr, 0), 0);
  return arena;
}

TEST(Allocator, AllThreadsShareOneArena) {
  ASSERT_NE(mallctl, nullptr) << "jemalloc is not the allocator";
  // Each arena keeps partly used huge pages of its own: one for all keeps the heap small.
  const auto here = std::make_unique<char[]>(64);
  const unsigned main = threadArena();
  unsigned other = main + 1;
  std::thread([&] {
    const auto there = std::make_unique<char[]>(64);
    other = threadArena();
  }).join();
  EXPECT_EQ(other, main);
}

}  // namespace
