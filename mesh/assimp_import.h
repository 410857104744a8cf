// Surface files that CGAL does not read, read by assimp behind an interface: assimp lives in a
// module of its own, libpolydg_assimp.so (mesh/assimp_import.cpp), loaded the first time such a
// file is read (readSurface, polydg/mesh/surface_io.h). Loading assimp and the libraries it
// pulls in took 7.5 ms of every polydg command's start.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace polydg {

/// One mesh of the file, its node transforms applied (assimp's PreTransformVertices).
struct ImportedMesh {
  std::vector<Eigen::Vector3d> vertices;  ///< assimp's single-precision positions, exactly
  std::vector<unsigned> faceSizes;        ///< the corners of each face
  std::vector<unsigned> corners;          ///< the faces' vertex indices, one face after another
};

/// What the module read: the meshes, or why it could not (`error`: what follows "PATH: " in the
/// message, with CGAL's reason `cgalReason` quoted if CGAL was tried first).
struct ImportedScene {
  std::string error;
  std::vector<ImportedMesh> meshes;
};

/// The module's entry point, looked up by this name: reads `path` into `out`.
using ImportWithAssimp = void (*)(const std::string& path, const std::string& cgalReason,
                                  ImportedScene& out);
inline constexpr const char* kImportWithAssimp = "polydg_import_with_assimp";

/// Reads `path` with the assimp module, loaded on first use as util/modules.h says. Throws
/// std::runtime_error, naming the places tried, if the module cannot be loaded.
ImportedScene importWithAssimp(const std::string& path, const std::string& cgalReason);

}  // namespace polydg
