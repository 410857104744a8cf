// The samples of the MLS surface embedding (polydg/physics/contact/embedding.h) and the sparse
// rows it is stored in, shared by the files that make the samples, fit the points' rows and
// update them after an edit.
#pragma once

#include <algorithm>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "physics/contact/hash_grid.h"
#include "polydg/physics/contact/embedding.h"

namespace polydg {

/// Sorts a sparse row by column and sums duplicate columns.
inline void compressRow(std::vector<std::pair<std::uint32_t, double>>& row) {
  // Stable: duplicates are summed in the order given (deterministic sums).
  std::stable_sort(row.begin(), row.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::size_t out = 0;
  for (std::size_t k = 0; k < row.size(); ++k) {
    if (out > 0 && row[out - 1].first == row[k].first)
      row[out - 1].second += row[k].second;
    else
      row[out++] = row[k];
  }
  row.resize(out);
}

/// The samples: positions, support radii, pieces and S in CSR form (sample q's row at
/// start[q] .. start[q + 1]), with the elements' pieces and bounds and the grids that find
/// elements and samples near a point.
struct SurfaceEmbedding::Samples {
  std::vector<Vec3> positions;
  std::vector<double> radius;
  std::vector<std::uint32_t> piece;
  std::vector<std::size_t> start{0};
  std::vector<std::uint32_t> columns;
  std::vector<double> values;
  std::size_t numPieces = 0;
  std::vector<std::uint32_t> elementPiece;
  std::vector<double> constant;  ///< phi_0 of each element: the basis's constant function
  /// The vertex samples of each element (ElementLinear).
  std::vector<std::size_t> elementSampleStart{0};
  std::vector<std::uint32_t> elementSamples;
  std::vector<Box3> boxes;
  HashGrid elementGrid, sampleGrid;
  std::unordered_map<std::uint64_t, std::uint32_t> vertexSample;  ///< (vertex << 32 | piece)
  double largestRadius = 0.0;

  void addRow(std::vector<std::pair<std::uint32_t, double>>& row) {
    compressRow(row);
    for (const auto& [c, v] : row) {
      columns.push_back(c);
      values.push_back(v);
    }
    start.push_back(columns.size());
  }
};

/// What computeRows() finds for each point it was given: its piece, the factor its supports
/// were widened by, whether it lies outside every element, and its Phi row.
struct SurfaceEmbedding::Rows {
  std::vector<std::uint32_t> piece;
  std::vector<float> widening;
  std::vector<bool> outside;
  std::vector<std::vector<std::pair<std::uint32_t, double>>> rows;
};

}  // namespace polydg
