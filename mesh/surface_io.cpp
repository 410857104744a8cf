// Reading surfaces through assimp: guard, import, bake transforms, weld by exact position,
// triangulate polygons exactly.
#include "mesh/surface_io.h"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <bit>
#include <cctype>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mesh/face_triangulation.h"

namespace polydg {

namespace {

/// Post-processing: apply node transforms (PreTransformVertices also joins meshes per material
/// and instantiates meshes used by several nodes) and reject scenes with inconsistent indices
/// or counts. Polygons are not triangulated by assimp (aiProcess_Triangulate): its ear clipping
/// turns some non-convex faces into overlapping triangles (testdata/Lprism.ply's top face).
constexpr unsigned kPostProcess = aiProcess_PreTransformVertices | aiProcess_ValidateDataStructure;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

/// `text` on one line: line breaks and runs of white space become one space, ends trimmed.
std::string oneLine(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (!out.empty() && out.back() != ' ') out += ' ';
    } else {
      out += c;
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out.empty() ? "unknown error" : out;
}

std::string assimpError(const std::string& message) {
  return "assimp cannot read it (" + oneLine(message) +
         "); check that it is a valid mesh file in a format assimp supports";
}

// --- header guard -----------------------------------------------------------------------------

/// The unsigned decimal `token` (saturated at the largest 64-bit value); `ok` is false if
/// `token` is not a plain unsigned decimal.
std::uint64_t parseCount(const std::string& token, bool& ok) {
  ok = !token.empty();
  std::uint64_t value = 0;
  for (char c : token) {
    if (!std::isdigit(static_cast<unsigned char>(c))) {
      ok = false;
      return 0;
    }
    const std::uint64_t digit = static_cast<std::uint64_t>(c - '0');
    if (value > (std::numeric_limits<std::uint64_t>::max() - digit) / 10)
      return std::numeric_limits<std::uint64_t>::max();
    value = 10 * value + digit;
  }
  return value;
}

/// assimp's OFF and PLY readers allocate what the header declares before reading the data, so
/// one corrupt count can take all memory (assimp's own invalid/OutOfMemory.off asks for 16 GB).
/// Every declared vertex, face or PLY element takes at least one byte of the file, so a header
/// declaring more of them than the file has bytes is rejected before assimp sees it.
void checkDeclaredCounts(const std::string& path, std::uintmax_t fileSize) {
  std::ifstream in(path, std::ios::binary);
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));

  const auto check = [&](const std::string& token, const std::string& what) {
    bool ok = false;
    const std::uint64_t count = parseCount(token, ok);
    if (ok && count > fileSize)
      fail(path, "header declares " + token + " " + what + " but the file has only " +
                     std::to_string(fileSize) + " bytes; the file is corrupt");
  };

  std::istringstream lines(head);
  std::string line;
  if (head.starts_with("ply")) {
    // "element NAME COUNT" lines up to end_header.
    while (std::getline(lines, line) && !line.starts_with("end_header")) {
      std::istringstream words(line);
      std::string keyword, name, count;
      if (words >> keyword >> name >> count && keyword == "element")
        check(count, "'" + name + "' elements");
    }
    return;
  }
  // OFF: a keyword ending in "OFF" (OFF, COFF, NOFF, ...), then the vertex and face counts;
  // '#' starts a comment.
  std::vector<std::string> tokens;
  while (tokens.size() < 3 && std::getline(lines, line)) {
    std::istringstream words(line.substr(0, line.find('#')));
    for (std::string word; tokens.size() < 3 && words >> word;) tokens.push_back(word);
  }
  if (tokens.size() < 3) return;
  std::string keyword = tokens[0];
  for (char& c : keyword) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (!keyword.ends_with("OFF")) return;
  check(tokens[1], "vertices");
  check(tokens[2], "faces");
}

// --- import -----------------------------------------------------------------------------------

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

/// Imports the file and post-processes it, or throws. Point clouds are recognised before
/// post-processing because validation rejects their face-less meshes with a cryptic message.
const aiScene* importScene(Assimp::Importer& importer, const std::string& path) {
  // Files holding only a skeleton or animation would otherwise get a made-up mesh of bones.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  // assimp reports errors by returning null; the catch is for anything that escapes it.
  const auto checked = [&](auto step) {
    const aiScene* scene = nullptr;
    try {
      scene = step();
    } catch (const std::exception& e) {
      fail(path, assimpError(e.what()));
    }
    if (scene == nullptr) fail(path, assimpError(importer.GetErrorString()));
    return scene;
  };
  const aiScene* raw = checked([&] { return importer.ReadFile(path.c_str(), 0); });
  if (!hasVertices(*raw)) fail(path, "contains no meshes");
  if (onlyPointsOrLines(*raw))
    fail(path, "contains only points/lines, no triangles; polydg needs a surface mesh");
  return checked([&] { return importer.ApplyPostProcessing(kPostProcess); });
}

// --- welding ----------------------------------------------------------------------------------

/// A coordinate widened to double, with -0.0 replaced by 0.0: after this, two coordinates are
/// equal exactly when their bits are.
double canonical(ai_real x) { return x == 0 ? 0.0 : static_cast<double>(x); }

/// The bits of a canonical position; the weld key.
using PositionKey = std::array<std::uint64_t, 3>;

struct PositionKeyHash {
  std::size_t operator()(const PositionKey& k) const noexcept {
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (std::uint64_t v : k) {
      h ^= v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
      h *= 0xff51afd7ed558ccdull;
    }
    return static_cast<std::size_t>(h ^ (h >> 33));
  }
};

PositionKey keyOf(const Vec3& p) {
  return {std::bit_cast<std::uint64_t>(p.x()), std::bit_cast<std::uint64_t>(p.y()),
          std::bit_cast<std::uint64_t>(p.z())};
}

/// Builds the surface: triangles go in as given, vertices are shared by exact position and
/// numbered in order of first use.
class SurfaceBuilder {
 public:
  SurfaceBuilder(const std::string& path, SurfaceReadInfo& info) : path_(path), info_(info) {}

  /// Adds triangle (a, b, c), or counts it as degenerate if two corners are at one position.
  void addTriangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const PositionKey ka = keyOf(a), kb = keyOf(b), kc = keyOf(c);
    if (ka == kb || kb == kc || kc == ka) {
      ++info_.droppedDegenerate;
      return;
    }
    surface_.triangles.push_back({id(ka, a), id(kb, b), id(kc, c)});
  }

  /// Adds the triangles of a planar polygon of four or more corners: its exact constrained
  /// triangulation (triangulateFace), or a fan from the first corner, counted, if it has zero
  /// area or crossing edges.
  void addPolygon(const std::vector<Vec3>& corners) {
    PolyMesh polygon;  // the polygon's distinct positions and one face through them
    std::unordered_map<PositionKey, VertexId, PositionKeyHash> local;
    Loop loop;
    for (const Vec3& p : corners) {
      auto [it, inserted] = local.try_emplace(keyOf(p));
      if (inserted) it->second = polygon.addVertex(p);
      loop.push_back(it->second);
    }
    std::vector<std::array<VertexId, 3>> triangles;
    if (local.size() >= 3) {
      const FaceId f = polygon.addFace({loop}, FaceOrigin::Surface);
      try {
        triangles = triangulateFace(polygon, f);
      } catch (const std::runtime_error&) {
        triangles.clear();
      }
    }
    if (triangles.empty()) {
      ++info_.fannedPolygons;
      for (std::size_t k = 1; k + 1 < loop.size(); ++k)
        triangles.push_back({loop[0], loop[k], loop[k + 1]});
    }
    for (const auto& t : triangles)
      addTriangle(polygon.position(t[0]), polygon.position(t[1]), polygon.position(t[2]));
  }

  TriangleSurface take() { return std::move(surface_); }
  std::size_t numTriangles() const { return surface_.triangles.size(); }
  std::size_t numVertices() const { return surface_.vertices.size(); }

 private:
  std::uint32_t id(const PositionKey& key, const Vec3& p) {
    auto [it, inserted] =
        welded_.try_emplace(key, static_cast<std::uint32_t>(surface_.vertices.size()));
    if (inserted) {
      if (surface_.vertices.size() == std::numeric_limits<std::uint32_t>::max())
        fail(path_, "has more than 2^32 - 1 distinct vertices; split the file");
      surface_.vertices.push_back(p);
    }
    return it->second;
  }

  const std::string& path_;
  SurfaceReadInfo& info_;
  TriangleSurface surface_;
  std::unordered_map<PositionKey, std::uint32_t, PositionKeyHash> welded_;
};

}  // namespace

TriangleSurface readSurface(const std::string& path, SurfaceReadInfo* info) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) fail(path, "no such file");
  if (fs::is_directory(status)) fail(path, "is a directory; give the path of a mesh file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec) checkDeclaredCounts(path, size);

  Assimp::Importer importer;
  const aiScene* scene = importScene(importer, path);

  SurfaceReadInfo counts;
  counts.meshes = scene->mNumMeshes;
  SurfaceBuilder builder(path, counts);
  std::size_t inputFaces = 0;  // faces with three or more corners
  std::vector<Vec3> corners;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& mesh = *scene->mMeshes[m];
    counts.inputVertices += mesh.mNumVertices;
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices == 1) {
        ++counts.ignoredPoints;
        continue;
      }
      if (face.mNumIndices == 2) {
        ++counts.ignoredLines;
        continue;
      }
      ++inputFaces;
      corners.clear();
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        const unsigned v = face.mIndices[k];
        if (v >= mesh.mNumVertices)
          fail(path, "mesh " + std::to_string(m) + " refers to vertex " + std::to_string(v) +
                         " of " + std::to_string(mesh.mNumVertices) + "; the file is corrupt");
        const aiVector3D& p = mesh.mVertices[v];
        corners.emplace_back(canonical(p.x), canonical(p.y), canonical(p.z));
        if (!corners.back().allFinite())
          fail(path, "a vertex has a non-finite coordinate (NaN or infinity); fix the file");
      }
      if (corners.size() == 3) {
        builder.addTriangle(corners[0], corners[1], corners[2]);
      } else {
        ++counts.polygons;
        builder.addPolygon(corners);
      }
    }
  }

  if (builder.numTriangles() == 0) {
    if (inputFaces == 0)
      fail(path, "contains only points/lines, no triangles; polydg needs a surface mesh");
    fail(path, "no face has three distinct vertices (" + std::to_string(inputFaces) +
                   " degenerate); polydg needs a surface mesh");
  }
  counts.weldedVertices = builder.numVertices();
  counts.triangles = builder.numTriangles();
  if (info != nullptr) *info = counts;
  return builder.take();
}

}  // namespace polydg
