// MeshEditor: cuts and sliver merges in place. Each operation is an Edit (edit.h) whose crossed
// elements a Splitter (piece_splitter.h) splits, checked by checkOperation()
// (operation_checks.h).
#include "polydg/cut/cut.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "cut/element_grid.h"
#include "cut/mesh_editor.h"
#include "edit.h"
#include "editor_state.h"
#include "mesh/plane_split.h"
#include "physics/checks/operation_checks.h"
#include "piece_splitter.h"
#include "polygon_test.h"
#include "util/stopwatch.h"

namespace polydg {

using namespace cut_detail;

std::size_t MeshEditor::raiseMomentDegree(int degree) {
  State& s = *state_;
  if (degree <= s.moments->degree()) return 0;
  s.retiredIntegrations += s.moments->facesIntegrated();
  s.moments = std::make_unique<MomentCache>(s.mesh, degree);
  s.moments->reserve(s.mesh.numFaces() + s.mesh.numFaces() / 4,
                     s.mesh.numElements() + s.mesh.numElements() / 4);
  return s.moments->update();
}

// --- MeshEditor --------------------------------------------------------------------------

MeshEditor::MeshEditor(PolyMesh mesh, double referenceVolume)
    : MeshEditor(std::move(mesh), referenceVolume, nullptr) {}

MeshEditor::MeshEditor(PolyMesh mesh, double referenceVolume, std::unique_ptr<MomentCache> moments)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.mesh = std::move(mesh);
  if (s.mesh.numElements() == 0) throw std::invalid_argument("MeshEditor: the mesh is empty");
  // Room to grow by a quarter in place before any array is copied (growth is amortized
  // after that, like any vector's).
  const auto headroom = [](std::size_t n) { return n + n / 4 + 64; };
  s.mesh.reserve(headroom(s.mesh.numVertices()), headroom(s.mesh.numFaces()),
                 headroom(s.mesh.numElements()));
  if (moments && moments->degree() >= 2) {
    s.moments = std::move(moments);
    s.moments->rebind(s.mesh);
  } else {
    s.moments = std::make_unique<MomentCache>(s.mesh, 2);
  }
  s.moments->reserve(headroom(s.mesh.numFaces()), headroom(s.mesh.numElements()));
  s.moments->update();
  std::vector<double> volumes(s.mesh.numElements());
  for (std::size_t e = 0; e < volumes.size(); ++e) {
    volumes[e] = s.moments->volume(ElementId(e));
    s.volume += volumes[e];
  }
  if (referenceVolume <= 0.0) {
    std::nth_element(volumes.begin(), volumes.begin() + volumes.size() / 2, volumes.end());
    referenceVolume = volumes[volumes.size() / 2];
  }
  if (!(referenceVolume > 0.0) || !std::isfinite(referenceVolume))
    throw std::invalid_argument("MeshEditor: the reference volume must be positive");
  s.referenceVolume = referenceVolume;
  s.grid = ElementGrid(s.mesh, std::cbrt(referenceVolume));
  s.region.assign(s.mesh.numElements(), 0);
  s.vertexPlane.assign(s.mesh.numVertices(), {});
}

MeshEditor::~MeshEditor() = default;
MeshEditor::MeshEditor(MeshEditor&&) noexcept = default;
MeshEditor& MeshEditor::operator=(MeshEditor&&) noexcept = default;

const PolyMesh& MeshEditor::mesh() const { return state_->mesh; }
const MomentCache& MeshEditor::moments() const { return *state_->moments; }

const MomentCache& MeshEditor::requireMoments(int degree) {
  if (!state_) throw std::logic_error("MeshEditor: used after release()");
  raiseMomentDegree(degree);
  return *state_->moments;
}

std::size_t MeshEditor::facesIntegrated() const {
  return state_->retiredIntegrations + state_->moments->facesIntegrated();
}
double MeshEditor::referenceVolume() const { return state_->referenceVolume; }
double MeshEditor::volume() const { return state_->volume; }

PolyMesh MeshEditor::release() {
  PolyMesh mesh = std::move(state_->mesh);
  state_.reset();
  return mesh;
}

namespace {

void checkOptions(const CutOptions& options) {
  if (options.removeSide < -1 || options.removeSide > 1)
    throw std::invalid_argument("removeSide must be -1, 0 or +1");
  if (!(options.sliverFraction >= 0.0) || !std::isfinite(options.sliverFraction))
    throw std::invalid_argument("the sliver fraction must be finite and not negative");
  if (options.checkDegree < 1 || options.checkDegree > 3)
    throw std::invalid_argument("the validation degree must be 1, 2 or 3");
}

/// A section's loops as points.
std::vector<std::vector<Vec3>> capLoops(const cut_detail::Splitter& splitter,
                                        const std::vector<PiecePolygon>& cap) {
  std::vector<std::vector<Vec3>> loops;
  for (const PiecePolygon& polygon : cap)
    for (std::size_t k = 0; k < polygon.numLoops(); ++k) {
      auto& loop = loops.emplace_back();
      for (std::size_t i = polygon.loopBegin(k); i < polygon.loopEnd[k]; ++i)
        loop.push_back(splitter.point(polygon.vertices[i]));
    }
  return loops;
}

}  // namespace

OperationReport MeshEditor::cut(const Blade& blade, const CutOptions& options) {
  checkOptions(options);
  if (!state_) throw std::logic_error("MeshEditor: used after release()");
  const Stopwatch start;
  try {
    return cutInPlace(blade, options);
  } catch (const std::exception& e) {
    // The splitter could not close a piece (constructions at round-off scale): the operation
    // fails like a failed check, and the part-edited mesh must not be used further.
    OperationReport report;
    report.op = blade.finite() ? "cut_polygon" : "cut";
    report.check.level = options.checks;
    report.check.passed = false;
    report.check.failure = std::string("split: ") + e.what();
    report.seconds = start.seconds();
    return report;
  }
}

OperationReport MeshEditor::cutInPlace(const Blade& blade, const CutOptions& options) {
  const Stopwatch start;
  State& s = *state_;
  OperationReport report;
  report.op = blade.finite() ? "cut_polygon" : "cut";
  report.facesReintegrated += raiseMomentDegree(2 * options.checkDegree);
  const double volumeBefore = s.volume;
  Edit edit(s.mesh, *s.moments, s.grid);
  const std::uint32_t planeId = planeIdOf(s, blade);
  s.vertexPlane.resize(s.mesh.numVertices());
  const std::size_t oldVertices = s.mesh.numVertices();
  VertexSides sides(s.mesh, blade, s.vertexPlane, planeId);
  const int removeSide = blade.finite() ? 0 : options.removeSide;
  std::optional<PolygonTest> polygon;
  if (blade.finite()) polygon.emplace(blade);

  // 1. Candidates from the grid, classified by their vertices' exact sides.
  std::vector<ElementId> candidates;
  {
    std::unordered_set<std::uint32_t> seen;
    s.grid.forEachNear(blade.normal, blade.offset, removeSide, [&](ElementId e) {
      if (seen.insert(e.value).second) candidates.push_back(e);
    });
    std::sort(candidates.begin(), candidates.end());
  }
  std::vector<ElementId> crossed, touching, wholeRemoved;
  for (ElementId e : candidates) {
    const auto [lo, hi] = sides.range(e);
    if (lo < 0 && hi > 0) crossed.push_back(e);
    if (lo <= 0 && hi >= 0) touching.push_back(e);
    if ((removeSide < 0 && hi <= 0) || (removeSide > 0 && lo >= 0)) wholeRemoved.push_back(e);
  }

  // 2. Faces lying in the plane (inside the polygon) decouple the elements on their sides.
  for (ElementId e : touching) {
    const FaceList uses = s.mesh.element(e).faces;
    for (const FaceUse& use : uses) {
      const Face& face = s.mesh.face(use.face);
      if (face.isBoundary()) continue;
      const auto [lo, hi] = sides.range(use.face);
      if (lo != 0 || hi != 0) continue;
      if (polygon && !std::all_of(face.vertices.begin(), face.vertices.end(),
                                  [&](VertexId v) { return polygon->inside(s.mesh.position(v)); }))
        continue;
      decouple(edit, use.face);
    }
  }

  // 3. Crossed elements: caps first (a finite blade splits only elements whose section lies
  //    in the polygon), then the pieces.
  Splitter splitter(edit, sides, blade, s.vertexPlane, planeId);
  splitter.setElements(crossed);
  std::vector<std::pair<ElementId, std::pair<Piece, Piece>>> toSplit;
  std::vector<ElementId> unsplit;  ///< crossed but kept whole
  for (ElementId e : crossed) {
    auto caps = splitter.caps(e);
    if (caps.first.empty() || caps.second.empty()) {
      // The section collapsed in rounding (the element is within round-off of the plane):
      // kept whole, like an element at a finite blade's edge.
      unsplit.push_back(e);
      continue;
    }
    if (polygon) {
      std::size_t in = 0, total = 0;
      for (const PiecePolygon& cap : caps.first)
        for (std::uint32_t v : cap.vertices) {
          ++total;
          in += polygon->inside(splitter.point(v));
        }
      if (in != total) {
        // At the polygon's edge, listed, if its section meets the polygon at all (a strip or a
        // polygon inside one section has no corner of it inside).
        if (in > 0 || polygon->meets(capLoops(splitter, caps.first))) edit.leftWhole().insert(e);
        unsplit.push_back(e);
        continue;
      }
    }
    toSplit.emplace_back(e, std::move(caps));
  }
  std::vector<std::pair<ElementId, int>> pieces;
  for (auto& [e, caps] : toSplit) {
    auto made = splitter.splitElement(e, caps);
    pieces.insert(pieces.end(), made.begin(), made.end());
  }
  report.elementsSplit = toSplit.size();
  report.piecesCreated = pieces.size();
  attachSplitFaceParts(edit, splitter);
  EdgePoints points;
  if (!toSplit.empty()) points = splitter.edgePoints();
  tagEdgePoints(s, points, oldVertices);
  // Edges the cut divided also bound faces of crossed elements kept whole.
  if (!unsplit.empty() && !toSplit.empty()) insertEdgePoints(edit, unsplit, points);
  report.facesReintegrated += edit.updateMoments();

  // 4. Removal of one side: whole elements (infinite blade) and pieces.
  if (options.removeSide != 0) {
    for (ElementId e : wholeRemoved) {
      report.volumeRemoved += edit.removeAndExpose(e);
      ++report.elementsRemoved;
    }
    for (const auto& [e, side] : pieces)
      if (side == options.removeSide) {
        report.volumeRemoved += edit.removeAndExpose(e);
        ++report.elementsRemoved;
      }
  }

  // 5. Slivers among the new pieces.
  if (options.sliverFraction > 0.0) {
    std::vector<ElementId> alive = edit.created().sorted();
    mergeSliverPieces(edit, std::move(alive), options.sliverFraction * s.referenceVolume, report);
  }

  // 6. Compaction, the grid, the volume, and 7. the checks.
  report.facesReintegrated += edit.updateMoments();
  finishOperation(s, edit, volumeBefore, options.checks, options.checkDegree,
                  options.sliverFraction * s.referenceVolume, report);
  report.seconds = start.seconds();
  return report;
}

namespace cut_detail {

std::uint32_t planeIdOf(MeshEditor::State& s, const Plane& plane) {
  std::uint32_t id = 0;
  while (id < s.planes.size() && !s.planes[id].sameAs(plane)) ++id;
  if (id == s.planes.size()) s.planes.push_back(plane);
  return id;
}

void attachSplitFaceParts(Edit& edit, Splitter& splitter) {
  PolyMesh& mesh = edit.mesh();
  for (auto& [id, parts] : splitter.splitFaces()) {
    const FaceId f(id);
    const ElementId front = mesh.face(f).front, back = mesh.face(f).back;
    for (const ElementId n : {front, back}) {
      if (!n.valid()) continue;
      const bool reversed = n == back;
      edit.touch(n);
      mesh.detachFace(n, f);
      for (int side : {-1, 1})
        for (std::size_t i = 0; i < (side < 0 ? parts.minus : parts.plus).size(); ++i)
          if (const FaceId part = splitter.subFace(f, side, i); part.valid())
            mesh.attachFace(n, {part, reversed});
    }
    edit.markDeadIfUnused(f);
  }
}

void tagEdgePoints(MeshEditor::State& s, const EdgePoints& points, std::size_t oldVertices) {
  // An end lies on a plane if it was made on it or lies on it exactly.
  auto onPlane = [&](std::uint32_t v, std::uint32_t t) {
    const PlaneTags& tags = s.vertexPlane[v];
    if (std::find(tags.begin(), tags.end(), t) != tags.end()) return true;
    return s.planes[t].side(s.mesh.position(VertexId(v))) == 0;
  };
  for (const auto& [edge, p] : points) {
    if (p.index() < oldVertices) continue;
    PlaneTags candidates = s.vertexPlane[edge.first];
    candidates.insert(candidates.end(), s.vertexPlane[edge.second].begin(),
                      s.vertexPlane[edge.second].end());
    PlaneTags& tags = s.vertexPlane[p.index()];
    for (std::uint32_t t : candidates)
      if (std::find(tags.begin(), tags.end(), t) == tags.end() && onPlane(edge.first, t) &&
          onPlane(edge.second, t))
        tags.push_back(t);
  }
}

void insertEdgePoints(Edit& edit, const std::vector<ElementId>& elements,
                      const EdgePoints& points) {
  PolyMesh& mesh = edit.mesh();
  for (ElementId e : elements) {
    const FaceList uses = mesh.element(e).faces;
    for (const FaceUse& use : uses) {
      bool changed = false;
      const Face face = mesh.face(use.face);
      for (std::size_t k = 0; k < face.numLoops(); ++k) {
        const auto loop = face.loop(k);
        for (std::size_t i = 0; i < loop.size(); ++i) {
          const VertexId a = loop[i], b = loop[(i + 1) % loop.size()];
          const auto it = points.find({std::min(a.value, b.value), std::max(a.value, b.value)});
          if (it != points.end()) changed |= mesh.splitEdge(use.face, a, b, it->second);
        }
      }
      if (changed) edit.refresh(use.face);
    }
  }
}

void finishOperation(MeshEditor::State& s, Edit& edit, double volumeBefore, CheckLevel level,
                     int degree, double sliverThreshold, OperationReport& report) {
  const double oldVolume = edit.oldVolume();
  edit.compact();
  double newVolume = 0.0;
  std::vector<ElementId> touched = edit.created().sorted();
  for (ElementId e : edit.changed().sorted()) touched.push_back(e);
  std::sort(touched.begin(), touched.end());
  for (ElementId e : touched) {
    newVolume += s.moments->volume(e);
    s.grid.insert(e, elementBounds(s.mesh, e));
  }
  s.volume = volumeBefore - oldVolume + newVolume;
  report.leftWhole = edit.leftWhole().sorted();
  report.lineage = edit.lineage();
  report.touched = touched;
  report.facesTotal = s.mesh.numFaces();
  OperationCheck& v = report.check;
  const Stopwatch checking;
  checkOperation(s.mesh, *s.moments, touched, s.region, level, degree, sliverThreshold, v);
  v.seconds = checking.seconds();
  v.volumeRelError =
      std::abs(volumeBefore - report.volumeRemoved - s.volume) / std::abs(volumeBefore);
  if (!(v.volumeRelError <= kVolumeBalanceTolerance)) {
    std::ostringstream msg;
    msg << "volume balance: relative error " << v.volumeRelError;
    if (v.passed) v.failure = msg.str();
    v.passed = false;
  }
}

}  // namespace cut_detail

OperationReport MeshEditor::mergeSlivers(double fraction, CheckLevel checks, int checkDegree) {
  CutOptions options;
  options.sliverFraction = fraction;
  options.checkDegree = checkDegree;
  checkOptions(options);
  if (!state_) throw std::logic_error("MeshEditor: used after release()");
  const Stopwatch start;
  State& s = *state_;
  OperationReport report;
  report.op = "merge";
  report.facesReintegrated += raiseMomentDegree(2 * checkDegree);
  const double volumeBefore = s.volume;
  Edit edit(s.mesh, *s.moments, s.grid);
  std::vector<ElementId> all(s.mesh.numElements());
  for (std::size_t e = 0; e < all.size(); ++e) all[e] = ElementId(e);
  if (fraction > 0.0) mergeSliverPieces(edit, std::move(all), fraction * s.referenceVolume, report);
  report.facesReintegrated += edit.updateMoments();
  finishOperation(s, edit, volumeBefore, checks, checkDegree, fraction * s.referenceVolume, report);
  report.seconds = start.seconds();
  return report;
}

}  // namespace polydg
