// The three encodings of VTU files, for tests that run once in each: the values and their names.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "polydg/mesh/vtu_io.h"

namespace polydg::testing {

/// Every VtuEncoding, as test parameters.
inline auto allEncodings() {
  return ::testing::Values(VtuEncoding::Ascii, VtuEncoding::Binary, VtuEncoding::Appended);
}

/// The name of a test run with encoding info.param: "Ascii", "Binary" or "Appended".
inline std::string encodingName(const ::testing::TestParamInfo<VtuEncoding>& info) {
  switch (info.param) {
    case VtuEncoding::Ascii: return "Ascii";
    case VtuEncoding::Binary: return "Binary";
    case VtuEncoding::Appended: return "Appended";
  }
  return "Unknown";
}

}  // namespace polydg::testing
