// What a body's contacts with its obstacles amount to at one state.
#pragma once

#include <cstddef>

namespace polydg {

/// Contacts at a state, measured (not linearized).
struct ContactMeasure {
  std::size_t contacts = 0;  ///< points inside an obstacle
  double deepest = 0.0;      ///< largest penetration -phi (0 if none)
  double energy = 0.0;       ///< sum k a phi^2 / 2 over penetrating points
};

}  // namespace polydg
