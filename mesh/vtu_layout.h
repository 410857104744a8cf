// What writeVtu() makes of a mesh alone, kept for writing many files of one mesh: a
// simulation's frames between edits. Private to polydg (model/time_series.cpp).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "polydg/mesh/vtu_io.h"

namespace polydg {

/// A mesh's cells as the file's streams (each element's corners, the points per side of a
/// cut, the face records) and its elements' signed volumes, made once: on the bunny sliced at
/// 40 cells they were a third of writing a frame (18-20 of 53 ms). `mesh` must outlive the
/// layout; the layout refuses a mesh whose counts of vertices, faces or elements changed since
/// (std::logic_error), the caller makes a new one after every edit.
class VtuLayout {
 public:
  /// Throws as writeVtu() does for a face with holes that cannot be triangulated.
  explicit VtuLayout(const PolyMesh& mesh);
  ~VtuLayout();
  VtuLayout(const VtuLayout&) = delete;
  VtuLayout& operator=(const VtuLayout&) = delete;

  const PolyMesh& mesh() const;
  /// Whether the layout is `mesh`'s as it is now (the same object with the same counts).
  bool fits(const PolyMesh& mesh) const;

 private:
  friend void writeVtu(const VtuLayout& layout, const std::string& path,
                       const VtuWriteOptions& options, const std::vector<CellArray>& cellData,
                       const std::vector<PointArray>& pointData,
                       const std::vector<CornerArray>& cornerData);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// writeVtu() of layout.mesh() with the layout's streams and volumes: the same bytes as
/// writeVtu(layout.mesh(), path, options, cellData, pointData, cornerData). Throws
/// std::logic_error if the mesh changed since the layout was made.
void writeVtu(const VtuLayout& layout, const std::string& path, const VtuWriteOptions& options,
              const std::vector<CellArray>& cellData, const std::vector<PointArray>& pointData,
              const std::vector<CornerArray>& cornerData);

}  // namespace polydg
