#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <tuple>

#include "mesh/face_triangulation.h"
#include "mesh/openfoam_quality.h"
#include "polydg/mesh/geometry.h"
#include "polydg/mesh/openfoam.h"
#include "polydg/util/error.h"

namespace polydg {

namespace {

namespace fs = std::filesystem;

/// One face as written: its corners (outward from the owner), owner, neighbour (-1 on the
/// boundary) and patch (-1 inside).
struct FoamFace {
  std::vector<std::uint32_t> corners;
  std::int64_t owner = 0, neighbour = -1;
  int patch = -1;
};

/// The patches in order: the caller's, then wall, cut0, cut1, ... (one per cut plane) and cut.
std::vector<std::string> patchNames(const OpenFoamOptions& options) {
  std::vector<std::string> names;
  std::set<std::string> seen;
  for (const OpenFoamPatch& p : options.patches) {
    // An OpenFOAM word: no whitespace, quotes, braces, parentheses or semicolons.
    const bool word = !p.name.empty() && std::none_of(p.name.begin(), p.name.end(), [](char c) {
      return std::isspace(static_cast<unsigned char>(c)) || std::strchr("\"'(){};/\\", c) ||
             static_cast<unsigned char>(c) < 0x20;
    });
    if (!word)
      throw InputError("patch name '" + p.name +
                       "' is not an OpenFOAM word; use letters, digits and _ only");
    if (!seen.insert(p.name).second)
      throw InputError("patch name '" + p.name + "' is given twice; give each patch one name");
    names.push_back(p.name);
  }
  std::vector<std::string> defaults{"wall"};
  for (std::size_t k = 0; k < options.cuts.size(); ++k)
    defaults.push_back("cut" + std::to_string(k));
  defaults.push_back("cut");
  for (const std::string& name : defaults) {
    if (seen.count(name))
      throw InputError("patch name '" + name +
                       "' is one of the default patches (wall, cut0, "
                       "cut1, ..., cut); choose another");
    names.push_back(name);
  }
  return names;
}

/// Which patch a boundary face goes to (an index into `names`): the first caller's patch that
/// selects it; else wall, or for a cut face the first cut whose plane it lies on (its vertices
/// within `tolerance` of it), else cut.
int patchOf(const PolyMesh& mesh, FaceId f, const OpenFoamOptions& options,
            const std::vector<std::string>& names, double tolerance) {
  for (std::size_t p = 0; p < options.patches.size(); ++p)
    if (options.patches[p].selects(f)) return static_cast<int>(p);
  const std::size_t wall = options.patches.size();
  const Face& face = mesh.face(f);
  if (face.origin != FaceOrigin::Cut) return static_cast<int>(wall);
  for (std::size_t k = 0; k < options.cuts.size(); ++k) {
    const Plane& c = options.cuts[k];
    const double norm = c.normal.norm();
    const bool on = std::all_of(face.vertices.begin(), face.vertices.end(), [&](VertexId v) {
      return std::abs(c.normal.dot(mesh.position(v)) - c.offset) <= tolerance * norm;
    });
    if (on) return static_cast<int>(wall + 1 + k);
  }
  return static_cast<int>(names.size() - 1);
}

/// The axis (0-2) and value of the axis-aligned plane holding all `corners`, or axis -1.
std::pair<int, double> axisPlaneOf(const PolyMesh& mesh,
                                   const std::vector<std::uint32_t>& corners) {
  for (int axis = 0; axis < 3; ++axis) {
    const double value = mesh.position(VertexId(corners[0]))[axis];
    if (std::all_of(corners.begin(), corners.end(),
                    [&](std::uint32_t v) { return mesh.position(VertexId(v))[axis] == value; }))
      return {axis, value};
  }
  return {-1, 0.0};
}

/// Boundary faces of one cell and patch on one axis-aligned plane (exactly: equal coordinates)
/// become one face where their union is one simple loop: the union of their directed edges
/// without the edges two of them share. A flat wall split into triangles then reaches OpenFOAM
/// as one polygon, whose centre its cell sees head-on, not as pieces off to the side.
void mergeCoplanarBoundaryFaces(const PolyMesh& mesh, std::vector<FoamFace>& faces) {
  std::map<std::tuple<std::int64_t, int, int, double>, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    if (faces[i].neighbour >= 0) continue;
    const auto [axis, value] = axisPlaneOf(mesh, faces[i].corners);
    if (axis >= 0) groups[{faces[i].owner, faces[i].patch, axis, value}].push_back(i);
  }
  std::vector<bool> dropped(faces.size(), false);
  for (const auto& [key, members] : groups) {
    if (members.size() < 2) continue;
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (std::size_t i : members) {
      const auto& c = faces[i].corners;
      for (std::size_t k = 0; k < c.size(); ++k) ++edges[{c[k], c[(k + 1) % c.size()]}];
    }
    std::map<std::uint32_t, std::uint32_t> next;
    bool simple = true;
    for (const auto& [edge, count] : edges) {
      const int twin =
          edges.count({edge.second, edge.first}) ? edges.at({edge.second, edge.first}) : 0;
      if (count > 1 || twin > 1) simple = false;
      if (twin == 1) continue;
      if (!next.emplace(edge.first, edge.second).second) simple = false;
    }
    if (!simple || next.empty()) continue;
    std::vector<std::uint32_t> loop{next.begin()->first};
    while (loop.size() <= next.size()) {
      const auto it = next.find(loop.back());
      if (it == next.end() || it->second == loop.front()) break;
      loop.push_back(it->second);
    }
    if (loop.size() != next.size() || next.at(loop.back()) != loop.front()) continue;
    faces[members[0]].corners = std::move(loop);
    for (std::size_t k = 1; k < members.size(); ++k) dropped[members[k]] = true;
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < faces.size(); ++i)
    if (!dropped[i]) {
      if (kept != i) faces[kept] = std::move(faces[i]);
      ++kept;
    }
  faces.resize(kept);
}

/// The mesh's faces as OpenFOAM's: split where they have holes, oriented out of the owner,
/// internal ones in upper-triangular order, then the boundary by patch.
std::vector<FoamFace> foamFaces(const PolyMesh& mesh, const OpenFoamOptions& options,
                                const std::vector<std::string>& names, std::size_t& splitFaces) {
  std::vector<FoamFace> out;
  out.reserve(mesh.numFaces());
  // A cut's points are its exact intersections rounded, possibly welded: within a few ulps of
  // the largest coordinate of its plane (see OpenFoamOptions::cuts).
  const Box3 bounds = meshBounds(mesh);
  const double largest = mesh.numVertices() ? std::max(bounds.min().cwiseAbs().maxCoeff(),
                                                       bounds.max().cwiseAbs().maxCoeff())
                                            : 0.0;
  const double tolerance =
      32.0 * (std::nextafter(largest, std::numeric_limits<double>::infinity()) - largest);
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
        throw InputError(
            "face " + std::to_string(f) + " of element " + std::to_string(face.front.value) +
            " (with holes) cannot be split into simple polygons for OpenFOAM: " + e.what() +
            "; run polydg check on the mesh");
      }
      for (const auto& t : triangles) polygons.push_back({t[0].value, t[1].value, t[2].value});
    }
    const int patch = face.back.valid() ? -1 : patchOf(mesh, FaceId(f), options, names, tolerance);
    for (std::vector<std::uint32_t>& corners : polygons) {
      FoamFace foam;
      foam.owner = face.front.value;
      foam.patch = patch;
      if (face.back.valid()) {
        foam.neighbour = face.back.value;
        if (foam.neighbour < foam.owner) {
          std::swap(foam.owner, foam.neighbour);
          std::reverse(corners.begin(), corners.end());
        }
      }
      foam.corners = std::move(corners);
      out.push_back(std::move(foam));
    }
  }
  mergeCoplanarBoundaryFaces(mesh, out);
  std::stable_sort(out.begin(), out.end(), [](const FoamFace& a, const FoamFace& b) {
    const bool ai = a.neighbour >= 0, bi = b.neighbour >= 0;
    if (ai != bi) return ai;
    if (ai) return std::tie(a.owner, a.neighbour) < std::tie(b.owner, b.neighbour);
    return std::tie(a.patch, a.owner) < std::tie(b.patch, b.owner);
  });
  return out;
}

/// Writes OpenFOAM files in one format: the FoamFile header, then lists of labels, vectors or
/// faces, as text or as raw little-endian bytes between the parentheses.
class FoamWriter {
 public:
  /// Files in `dir`, which OpenFOAM knows as `location` (constant/polyMesh, system).
  FoamWriter(const fs::path& dir, bool binary, std::string location)
      : dir_(dir), binary_(binary), location_(std::move(location)) {}

  void labels(const char* object, const std::vector<std::uint32_t>& values,
              const std::string& note = "") {
    std::string text = header("labelList", object, note);
    appendLabels(text, values);
    write(object, text);
  }

  void points(const std::vector<Vec3>& points) {
    std::string text = header("vectorField", "points");
    text += std::to_string(points.size()) + "\n(";
    if (binary_) {
      if (!points.empty()) {
        std::vector<double> raw;
        raw.reserve(3 * points.size());
        for (const Vec3& p : points) raw.insert(raw.end(), {p.x(), p.y(), p.z()});
        text.append(reinterpret_cast<const char*>(raw.data()), raw.size() * sizeof(double));
      }
    } else {
      text += "\n";
      char line[96];
      for (const Vec3& p : points) {
        std::snprintf(line, sizeof line, "(%.17g %.17g %.17g)\n", p.x(), p.y(), p.z());
        text += line;
      }
    }
    text += ")\n";
    write("points", text);
  }

  /// Faces: a faceList in ASCII, a faceCompactList (offsets, then all corners) in binary.
  void faces(const std::vector<std::vector<std::uint32_t>>& faces) {
    std::string text = header(binary_ ? "faceCompactList" : "faceList", "faces");
    if (binary_) {
      std::vector<std::uint32_t> offsets{0}, corners;
      for (const auto& f : faces) {
        corners.insert(corners.end(), f.begin(), f.end());
        offsets.push_back(static_cast<std::uint32_t>(corners.size()));
      }
      appendLabels(text, offsets);
      appendLabels(text, corners);
    } else {
      text += std::to_string(faces.size()) + "\n(\n";
      for (const auto& f : faces) {
        text += std::to_string(f.size()) + "(";
        for (std::size_t k = 0; k < f.size(); ++k) text += (k ? " " : "") + std::to_string(f[k]);
        text += ")\n";
      }
      text += ")\n";
    }
    write("faces", text);
  }

  void text(const char* cls, const char* object, const std::string& body) {
    write(object, header(cls, object) + body);
  }

 private:
  std::string header(const char* cls, const char* object, const std::string& note = "") const {
    std::string h = "FoamFile\n{\n    version     2.0;\n    format      ";
    h += binary_ ? "binary;\n    arch        \"LSB;label=32;scalar=64\";\n" : "ascii;\n";
    h += std::string("    class       ") + cls + ";\n";
    if (!note.empty()) h += "    note        \"" + note + "\";\n";
    h += "    location    \"" + location_ + "\";\n    object      " + object + ";\n}\n\n";
    return h;
  }

  void appendLabels(std::string& text, const std::vector<std::uint32_t>& values) const {
    text += std::to_string(values.size());
    if (binary_) {
      // OpenFOAM reads no parentheses around an empty binary list.
      if (!values.empty()) {
        text += "\n(";
        text.append(reinterpret_cast<const char*>(values.data()),
                    values.size() * sizeof(std::uint32_t));
        text += ")";
      }
      text += "\n";
      return;
    }
    text += "\n(\n";
    for (std::uint32_t v : values) text += std::to_string(v) + "\n";
    text += ")\n";
  }

  void write(const char* object, const std::string& text) const {
    const fs::path path = dir_ / object;
    std::ofstream os(path, std::ios::binary);
    os << text;
    os.close();
    if (!os) throw OutputError("cannot write " + path.string() + "; check the folder");
  }

  fs::path dir_;
  bool binary_;
  std::string location_;
};

/// The dictionaries OpenFOAM's tools read before they open a mesh (always ASCII).
void writeSystem(const fs::path& dir) {
  FoamWriter w(dir, false, "system");
  w.text("dictionary", "controlDict",
         "application     none;\nstartFrom       startTime;\nstartTime       0;\n"
         "stopAt          endTime;\nendTime         1;\ndeltaT          1;\n"
         "writeControl    timeStep;\nwriteInterval   1;\nwritePrecision  17;\n");
  w.text("dictionary", "fvSchemes",
         "ddtSchemes { default Euler; }\ngradSchemes { default Gauss linear; }\n"
         "divSchemes { default none; }\nlaplacianSchemes { default Gauss linear "
         "corrected; }\ninterpolationSchemes { default linear; }\nsnGradSchemes { "
         "default corrected; }\n");
  w.text("dictionary", "fvSolution", "solvers { }\n");
}

}  // namespace

OpenFoamReport writeOpenFoamCase(const PolyMesh& mesh, const std::string& caseDir,
                                 const OpenFoamOptions& options) {
  OpenFoamReport report;
  report.binary = options.binary;
  const std::vector<std::string> names = patchNames(options);
  const std::vector<FoamFace> faces = foamFaces(mesh, options, names, report.splitFaces);
  constexpr std::size_t kMaxLabel = std::numeric_limits<std::int32_t>::max();
  if (mesh.numElements() > kMaxLabel || faces.size() > kMaxLabel || mesh.numVertices() > kMaxLabel)
    throw InputError(
        "the mesh has more cells, faces or points than OpenFOAM's 32-bit labels "
        "hold; split it or mesh it coarser");

  // Points: those the faces use, in order.
  OpenFoamFaces foam;
  foam.cells = mesh.numElements();
  std::vector<std::int64_t> index(mesh.numVertices(), -1);
  for (const FoamFace& f : faces)
    for (std::uint32_t v : f.corners) index[v] = 0;
  for (std::size_t v = 0; v < mesh.numVertices(); ++v) {
    if (index[v] < 0) continue;
    index[v] = static_cast<std::int64_t>(foam.points.size());
    foam.points.push_back(mesh.position(VertexId(v)));
  }
  std::vector<std::size_t> patchFaces(names.size(), 0);
  for (const FoamFace& f : faces) {
    std::vector<std::uint32_t> corners;
    corners.reserve(f.corners.size());
    for (std::uint32_t v : f.corners) corners.push_back(static_cast<std::uint32_t>(index[v]));
    foam.corners.push_back(std::move(corners));
    foam.owner.push_back(static_cast<std::uint32_t>(f.owner));
    if (f.neighbour >= 0) {
      foam.neighbour.push_back(static_cast<std::uint32_t>(f.neighbour));
    } else {
      ++patchFaces[static_cast<std::size_t>(f.patch)];
      foam.patch.push_back(names[static_cast<std::size_t>(f.patch)]);
    }
  }
  report.cells = foam.cells;
  report.points = foam.points.size();
  report.faces = faces.size();
  report.internalFaces = foam.neighbour.size();

  std::string boundary;
  std::size_t start = report.internalFaces, nonEmpty = 0;
  for (std::size_t p = 0; p < names.size(); ++p) {
    if (patchFaces[p] == 0) continue;
    ++nonEmpty;
    boundary += names[p] + "\n{\n    type            wall;\n    inGroups        1(wall);\n" +
                "    nFaces          " + std::to_string(patchFaces[p]) + ";\n    startFace       " +
                std::to_string(start) + ";\n}\n";
    report.patches.push_back({names[p], patchFaces[p]});
    start += patchFaces[p];
  }
  report.quality = openFoamQuality(foam);

  const fs::path target(caseDir);
  const fs::path staging = target.string() + ".tmp-" + std::to_string(::getpid());
  std::error_code ec;
  if (fs::exists(target) && !fs::is_directory(target / "constant" / "polyMesh"))
    throw InputError(caseDir + " exists and is not an OpenFOAM case; choose another -o");
  fs::remove_all(staging, ec);
  fs::create_directories(staging / "constant" / "polyMesh", ec);
  fs::create_directories(staging / "system", ec);
  if (ec) throw InputError("cannot create " + staging.string() + ": " + ec.message());
  try {
    FoamWriter w(staging / "constant" / "polyMesh", options.binary, "constant/polyMesh");
    w.points(foam.points);
    w.faces(foam.corners);
    const std::string note = "nPoints:" + std::to_string(report.points) +
                             "  nCells:" + std::to_string(report.cells) +
                             "  nFaces:" + std::to_string(report.faces) +
                             "  nInternalFaces:" + std::to_string(report.internalFaces);
    w.labels("owner", foam.owner, note);
    w.labels("neighbour", foam.neighbour, note);
    w.text("polyBoundaryMesh", "boundary", std::to_string(nonEmpty) + "\n(\n" + boundary + ")\n");
    writeSystem(staging / "system");
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }
  fs::remove_all(target, ec);
  fs::rename(staging, target, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove_all(staging, ec);
    throw InputError("cannot rename " + staging.string() + " to " + caseDir + ": " + why);
  }
  return report;
}

}  // namespace polydg
