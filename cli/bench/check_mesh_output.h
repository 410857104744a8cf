// The figures of OpenFOAM's checkMesh read from what it prints, so that the openfoam suite
// reports OpenFOAM's own verdict on both meshers' cases.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace polydg::bench {

struct CheckMeshSummary {
  /// "Mesh OK", "Failed N mesh checks", or "no verdict" when checkMesh printed neither (it
  /// failed before its checks ended).
  std::string verdict = "no verdict";
  int failedChecks = 0;  ///< N of "Failed N mesh checks."
  std::optional<std::size_t> cells;
  std::optional<double> totalVolume;          ///< "Total volume = V."
  std::optional<double> maxNonOrthogonality;  ///< degrees, "Mesh non-orthogonality Max: X"
  std::optional<double> maxSkewness;          ///< "Max skewness = X", failing or not
  std::optional<double> maxAspectRatio;       ///< "Max aspect ratio = X", or ": X" when failing
  /// The lines checkMesh marks as failed checks (" ***..."), without the stars.
  std::vector<std::string> failures;
};

/// Reads the mesh statistics and checks from checkMesh's output `text` (OpenFOAM v1912's
/// wording). Figures it does not find stay empty.
CheckMeshSummary parseCheckMesh(const std::string& text);

}  // namespace polydg::bench
