// polydg's assimp module, libpolydg_assimp.so (mesh/assimp_import.h): the one file that includes
// assimp. It links none of polydg's libraries.
#include "mesh/assimp_import.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <exception>
#include <string>

#include "util/format.h"

namespace polydg {

namespace {

/// Post-processing: apply node transforms (PreTransformVertices also joins meshes per material
/// and instantiates meshes used by several nodes) and reject scenes with inconsistent indices
/// or counts. Polygons are not triangulated by assimp (aiProcess_Triangulate): its ear clipping
/// turns some non-convex faces into overlapping triangles (testdata/Lprism.ply's top face).
constexpr unsigned kPostProcess = aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure;

/// assimp's reason, and CGAL's if CGAL was tried first (`cgalReason` not empty).
std::string assimpError(const std::string& message, const std::string& cgalReason) {
  return "assimp cannot read it (" + oneLine(message) + ")" +
         (cgalReason.empty() ? "" : "; nor can CGAL (" + oneLine(cgalReason) + ")") +
         "; check that it is a valid mesh file in a format assimp supports";
}

/// True if some mesh has a vertex. Safe on a scene that has not been validated yet.
bool hasVertices(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes ? scene.mMeshes[m] : nullptr;
    if (mesh != nullptr && mesh->mNumVertices > 0) return true;
  }
  return false;
}

/// True if the scene holds only point clouds, points and lines: no face has three or more
/// corners, and none is malformed (no corners). Safe on a scene that has not been validated.
bool onlyPointsOrLines(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes ? scene.mMeshes[m] : nullptr;
    if (mesh == nullptr || mesh->mNumFaces == 0) continue;
    if (mesh->mFaces == nullptr) return false;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const unsigned corners = mesh->mFaces[f].mNumIndices;
      if (corners == 0 || corners >= 3) return false;
    }
  }
  return true;
}

/// Imports the file and post-processes it, or says why not in `error`. Point clouds are
/// recognised before post-processing because validation rejects their face-less meshes with a
/// cryptic message.
const aiScene* importScene(Assimp::Importer& importer, const std::string& path,
                           const std::string& cgalReason, std::string& error) {
  // Files holding only a skeleton or animation would otherwise get a made-up mesh of bones.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  // assimp reports errors by returning null; the catch is for anything that escapes it.
  const auto checked = [&](auto step) {
    const aiScene* scene = nullptr;
    try {
      scene = step();
    } catch (const std::exception& e) {
      error = assimpError(e.what(), cgalReason);
      return static_cast<const aiScene*>(nullptr);
    }
    if (scene == nullptr) error = assimpError(importer.GetErrorString(), cgalReason);
    return scene;
  };
  const aiScene* raw = checked([&] { return importer.ReadFile(path.c_str(), 0); });
  if (raw == nullptr) return nullptr;
  if (!hasVertices(*raw)) {
    error = "contains no meshes";
    return nullptr;
  }
  if (onlyPointsOrLines(*raw)) {
    error = "contains only points/lines, no triangles; polydg needs a surface mesh";
    return nullptr;
  }
  return checked([&] { return importer.ApplyPostProcessing(kPostProcess); });
}

}  // namespace

}  // namespace polydg

extern "C" __attribute__((visibility("default"))) void polydg_import_with_assimp(
    const std::string& path, const std::string& cgalReason, polydg::ImportedScene& out) {
  out = polydg::ImportedScene();
  try {
    Assimp::Importer importer;
    const aiScene* scene = polydg::importScene(importer, path, cgalReason, out.error);
    if (scene == nullptr) return;
    out.meshes.resize(scene->mNumMeshes);
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh& mesh = *scene->mMeshes[m];
      polydg::ImportedMesh& to = out.meshes[m];
      to.vertices.reserve(mesh.mNumVertices);
      for (unsigned v = 0; v < mesh.mNumVertices; ++v)
        to.vertices.emplace_back(mesh.mVertices[v].x, mesh.mVertices[v].y, mesh.mVertices[v].z);
      to.faceSizes.reserve(mesh.mNumFaces);
      for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
        const aiFace& face = mesh.mFaces[f];
        to.faceSizes.push_back(face.mNumIndices);
        to.corners.insert(to.corners.end(), face.mIndices, face.mIndices + face.mNumIndices);
      }
    }
  } catch (const std::exception& e) {
    out = polydg::ImportedScene();
    out.error = polydg::assimpError(e.what(), cgalReason);
  }
}
