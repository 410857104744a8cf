// cli/allocator.cpp: the polydg program's operator new advises large blocks onto huge pages
// and leaves small ones on the heap's pages (read back from the kernel's /proc/self/smaps).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

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

TEST(Allocator, LargeBlocksAreAdvisedOntoHugePagesAndSmallOnesAreNot) {
  if (!std::filesystem::exists("/sys/kernel/mm/transparent_hugepage"))
    GTEST_SKIP() << "this kernel has no transparent huge pages";
  constexpr std::size_t kHuge = std::size_t(2) << 20;
  // Just below the size advised: large enough to hold a whole huge page (a large block is
  // page-aligned), which must be left alone.
  const auto small = std::make_unique<char[]>(polydg::kHugePagesAtLeast - 4096);
  const auto large = std::make_unique<char[]>(std::size_t(16) << 20);
  EXPECT_TRUE(advisedOntoHugePages(firstHugePageIn(large.get())));
  EXPECT_TRUE(advisedOntoHugePages(large.get() + (std::size_t(16) << 20) - kHuge - 1));
  EXPECT_FALSE(advisedOntoHugePages(firstHugePageIn(small.get())));
  const std::vector<char> containers(std::size_t(12) << 20);  // through std::allocator
  EXPECT_TRUE(advisedOntoHugePages(firstHugePageIn(containers.data())));
  const auto nothrowLarge = std::unique_ptr<char[]>(new (std::nothrow) char[std::size_t(8) << 20]);
  ASSERT_NE(nothrowLarge, nullptr);
  EXPECT_TRUE(advisedOntoHugePages(firstHugePageIn(nothrowLarge.get())));
}

}  // namespace
