// Arguments that hold an optional value per element (volumes, flags): either nothing, or one for
// every element of the mesh.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "polydg/mesh/poly_mesh.h"

namespace polydg {

/// Throws std::invalid_argument("WHO: N WHAT given for M elements") unless `given` is 0 (none
/// given) or the mesh's number of elements.
inline void requireNoneOrOnePerElement(std::size_t given, const PolyMesh& mesh, const char* who,
                                       const char* what) {
  if (given != 0 && given != mesh.numElements())
    throw std::invalid_argument(std::string(who) + ": " + std::to_string(given) + " " + what +
                                " given for " + std::to_string(mesh.numElements()) + " elements");
}

}  // namespace polydg
