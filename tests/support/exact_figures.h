// Comparing a figure with its exact value: the volumes and areas of surfaces whose coordinates
// are exact (integers or dyadic numbers), which polydg computes to round-off.
#pragma once

#include <cmath>

namespace polydg::testing {

/// The relative error a figure of exact coordinates may have: round-off.
inline constexpr double kExactRelTol = 1e-12;

/// |value - exact| / |exact|.
inline double relativeError(double value, double exact) {
  return std::abs(value - exact) / std::abs(exact);
}

}  // namespace polydg::testing
