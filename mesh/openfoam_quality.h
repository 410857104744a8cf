// OpenFOAM's checkMesh figures (v1912: its face and cell centres, non-orthogonality, skewness,
// face pyramids, aspect ratio, and the thresholds of its default checks) for faces about to be
// written by writeOpenFoamCase.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/openfoam.h"

namespace polydg {

/// Faces in OpenFOAM's layout: corners (indices into `points`), outward from the owner; the
/// first `internalFaces` have a neighbour; `patch[f - internalFaces]` names boundary face f's
/// patch.
struct OpenFoamFaces {
  std::vector<Vec3> points;
  std::vector<std::vector<std::uint32_t>> corners;
  std::vector<std::uint32_t> owner, neighbour;
  std::vector<std::string> patch;
  std::size_t cells = 0;
};

OpenFoamQuality openFoamQuality(const OpenFoamFaces& faces);

}  // namespace polydg
