// checkTetMesh (polydg/mesh/tet_mesh.h) for the readers: messages that call tets and vertices by
// the numbers their file gives them, and the orientation fix-up the readers run first.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "polydg/mesh/tet_mesh.h"

namespace polydg {

/// How messages name a mesh's tets and vertices: "element 17" and "node 4" for a Gmsh file,
/// whose tags are neither 0-based nor contiguous; the defaults give "tet t" and "vertex v".
struct TetNaming {
  std::string file;                         ///< messages start "file: " when not empty
  std::string tetWord = "tet";              ///< "tet", "element", "cell"
  std::vector<std::int64_t> tetNumbers;     ///< file number of tet t; empty: t itself
  std::string vertexWord = "vertex";        ///< "vertex", "node", "point"
  std::vector<std::int64_t> vertexNumbers;  ///< file number of vertex v; empty: v itself

  std::string tet(std::size_t t) const;
  std::string vertex(std::size_t v) const;
};

/// checkTetMesh with `naming`'s words and numbers in its messages.
void checkTetMesh(const TetMesh& mesh, const TetNaming& naming);

/// Swaps the last two corners of each tet that CGAL's exact orientation finds negative, so
/// that files of either orientation convention read alike; flat tets are left for the check.
/// Corner indices must be in range.
void orientTets(TetMesh& mesh);

}  // namespace polydg
