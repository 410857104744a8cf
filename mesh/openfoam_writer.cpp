#include "polydg/mesh/openfoam.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <tuple>

#include "mesh/face_triangulation.h"
#include "polydg/util/error.h"

namespace polydg {

namespace {

namespace fs = std::filesystem;

constexpr std::array<const char*, 2> kPatches = {"wall", "cut"};

/// One face as written: its corners (outward from the owner), owner, neighbour (-1 on the
/// boundary) and patch (-1 inside).
struct FoamFace {
  std::vector<std::uint32_t> corners;
  std::int64_t owner = 0, neighbour = -1;
  int patch = -1;
};

int patchOf(FaceOrigin origin) { return origin == FaceOrigin::Cut ? 1 : 0; }

std::string header(const char* cls, const char* object, const char* location) {
  return std::string("FoamFile\n{\n    version     2.0;\n    format      ascii;\n    class       ") +
         cls + ";\n    location    \"" + location + "\";\n    object      " + object + ";\n}\n\n";
}

/// The mesh's faces as OpenFOAM's: split where they have holes, oriented out of the owner,
/// internal ones in upper-triangular order, then the boundary by patch.
std::vector<FoamFace> foamFaces(const PolyMesh& mesh, std::size_t& splitFaces) {
  std::vector<FoamFace> out;
  out.reserve(mesh.numFaces());
  for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
    const Face& face = mesh.face(FaceId(f));
    if (!face.front.valid()) continue;  // used by no element
    std::vector<std::vector<std::uint32_t>> polygons;
    if (face.numLoops() == 1) {
      std::vector<std::uint32_t> loop;
      for (VertexId v : face.vertices) loop.push_back(v.value);
      polygons.push_back(std::move(loop));
    } else {
      ++splitFaces;
      std::vector<std::array<VertexId, 3>> triangles;
      try {
        triangles = triangulateFace(mesh, FaceId(f));
      } catch (const std::runtime_error& e) {
        throw InputError("face " + std::to_string(f) + " (with holes) cannot be split into simple "
                         "polygons for OpenFOAM: " + e.what());
      }
      for (const auto& t : triangles) polygons.push_back({t[0].value, t[1].value, t[2].value});
    }
    for (std::vector<std::uint32_t>& corners : polygons) {
      FoamFace foam;
      foam.owner = face.front.value;
      if (face.back.valid()) {
        foam.neighbour = face.back.value;
        if (foam.neighbour < foam.owner) {
          std::swap(foam.owner, foam.neighbour);
          std::reverse(corners.begin(), corners.end());
        }
      } else {
        foam.patch = patchOf(face.origin);
      }
      foam.corners = std::move(corners);
      out.push_back(std::move(foam));
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const FoamFace& a, const FoamFace& b) {
    const bool ai = a.neighbour >= 0, bi = b.neighbour >= 0;
    if (ai != bi) return ai;
    if (ai) return std::tie(a.owner, a.neighbour) < std::tie(b.owner, b.neighbour);
    return std::tie(a.patch, a.owner) < std::tie(b.patch, b.owner);
  });
  return out;
}

void writeFile(const fs::path& path, const std::string& text) {
  std::ofstream os(path, std::ios::binary);
  os << text;
  os.close();
  if (!os) throw InputError("cannot write " + path.string() + "; check the folder");
}

void writeSystem(const fs::path& dir) {
  writeFile(dir / "controlDict",
            header("dictionary", "controlDict", "system") +
                "application     none;\nstartFrom       startTime;\nstartTime       0;\n"
                "stopAt          endTime;\nendTime         1;\ndeltaT          1;\n"
                "writeControl    timeStep;\nwriteInterval   1;\n");
  writeFile(dir / "fvSchemes",
            header("dictionary", "fvSchemes", "system") +
                "ddtSchemes { default Euler; }\ngradSchemes { default Gauss linear; }\n"
                "divSchemes { default none; }\nlaplacianSchemes { default Gauss linear "
                "corrected; }\ninterpolationSchemes { default linear; }\nsnGradSchemes { "
                "default corrected; }\n");
  writeFile(dir / "fvSolution", header("dictionary", "fvSolution", "system") + "solvers { }\n");
}

}  // namespace

OpenFoamReport writeOpenFoamCase(const PolyMesh& mesh, const std::string& caseDir) {
  OpenFoamReport report;
  const std::vector<FoamFace> faces = foamFaces(mesh, report.splitFaces);
  // Points: those the faces use, in order.
  std::vector<std::int64_t> index(mesh.numVertices(), -1);
  for (const FoamFace& f : faces)
    for (std::uint32_t v : f.corners) index[v] = 0;
  std::string points;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v) {
    if (index[v] < 0) continue;
    index[v] = static_cast<std::int64_t>(report.points++);
    char line[96];
    const Vec3& p = mesh.position(VertexId(v));
    std::snprintf(line, sizeof line, "(%.17g %.17g %.17g)\n", p.x(), p.y(), p.z());
    points += line;
  }
  std::string faceText, owner, neighbour;
  std::array<std::size_t, kPatches.size()> patchFaces{};
  for (const FoamFace& f : faces) {
    faceText += std::to_string(f.corners.size()) + "(";
    for (std::size_t k = 0; k < f.corners.size(); ++k)
      faceText += (k ? " " : "") + std::to_string(index[f.corners[k]]);
    faceText += ")\n";
    owner += std::to_string(f.owner) + "\n";
    if (f.neighbour >= 0) {
      neighbour += std::to_string(f.neighbour) + "\n";
      ++report.internalFaces;
    } else {
      ++patchFaces[static_cast<std::size_t>(f.patch)];
    }
  }
  report.cells = mesh.numElements();
  report.faces = faces.size();
  std::string boundary;
  std::size_t start = report.internalFaces, nonEmpty = 0;
  for (std::size_t p = 0; p < kPatches.size(); ++p) {
    if (patchFaces[p] == 0) continue;
    ++nonEmpty;
    boundary += std::string(kPatches[p]) + "\n{\n    type            wall;\n    inGroups        1(wall);\n    nFaces          " +
                std::to_string(patchFaces[p]) + ";\n    startFace       " + std::to_string(start) +
                ";\n}\n";
    report.patches.push_back({kPatches[p], patchFaces[p]});
    start += patchFaces[p];
  }
  const fs::path target(caseDir);
  const fs::path staging = target.string() + ".tmp-" + std::to_string(::getpid());
  std::error_code ec;
  if (fs::exists(target) && !fs::is_directory(target / "constant" / "polyMesh"))
    throw InputError(caseDir + " exists and is not an OpenFOAM case; choose another -o");
  fs::remove_all(staging, ec);
  fs::create_directories(staging / "constant" / "polyMesh", ec);
  fs::create_directories(staging / "system", ec);
  if (ec) throw InputError("cannot create " + staging.string() + ": " + ec.message());
  const fs::path poly = staging / "constant" / "polyMesh";
  writeFile(poly / "points", header("vectorField", "points", "constant/polyMesh") +
                                 std::to_string(report.points) + "\n(\n" + points + ")\n");
  writeFile(poly / "faces", header("faceList", "faces", "constant/polyMesh") +
                                std::to_string(report.faces) + "\n(\n" + faceText + ")\n");
  writeFile(poly / "owner", header("labelList", "owner", "constant/polyMesh") +
                                std::to_string(report.faces) + "\n(\n" + owner + ")\n");
  writeFile(poly / "neighbour", header("labelList", "neighbour", "constant/polyMesh") +
                                    std::to_string(report.internalFaces) + "\n(\n" + neighbour +
                                    ")\n");
  writeFile(poly / "boundary", header("polyBoundaryMesh", "boundary", "constant/polyMesh") +
                                   std::to_string(nonEmpty) + "\n(\n" + boundary + ")\n");
  writeSystem(staging / "system");
  fs::remove_all(target, ec);
  fs::rename(staging, target, ec);
  if (ec) throw InputError("cannot rename " + staging.string() + " to " + caseDir + ": " + ec.message());
  return report;
}

}  // namespace polydg
