// MeshEditor::refine: elements split by their own planes with the new faces kept coupled
// (paper section 10, "Dynamic Adaptivity"). Each round groups the elements by plane, so that
// a face two of them share is split once for both; the splitter's caps become interior faces
// (Splitter::coupleCaps); neighbours left whole take the parts of the faces split under them
// and the new points on every edge around a split edge, so faces stay shared exactly.
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "cut/mesh_editor.h"
#include "edit.h"
#include "editor_state.h"
#include "physics/checks/operation_checks.h"
#include "piece_splitter.h"
#include "polydg/cut/cut.h"
#include "util/stopwatch.h"

namespace polydg {

using namespace cut_detail;

namespace {

/// Elements around the edges that `points` divided, reached from `start` through faces that
/// hold such an edge or a part of it: every element whose faces must take the new points.
std::vector<ElementId> elementsAroundEdges(const PolyMesh& mesh,
                                           const std::vector<ElementId>& start,
                                           const EdgePoints& points) {
  std::unordered_map<std::uint32_t, std::pair<std::uint32_t, std::uint32_t>> edgeOf;
  for (const auto& [edge, p] : points) edgeOf.emplace(p.value, edge);
  auto holdsEdge = [&](VertexId u, VertexId w) {
    const std::pair<std::uint32_t, std::uint32_t> key{std::min(u.value, w.value),
                                                      std::max(u.value, w.value)};
    if (points.count(key)) return true;
    for (const auto& [m, x] : {std::pair{u, w}, std::pair{w, u}}) {
      const auto it = edgeOf.find(m.value);
      if (it != edgeOf.end() && (it->second.first == x.value || it->second.second == x.value))
        return true;
    }
    return false;
  };
  std::unordered_set<std::uint32_t> seen;
  std::deque<ElementId> queue;
  for (ElementId e : start)
    if (seen.insert(e.value).second) queue.push_back(e);
  std::vector<ElementId> out;
  while (!queue.empty()) {
    const ElementId e = queue.front();
    queue.pop_front();
    out.push_back(e);
    for (const FaceUse& use : mesh.element(e).faces) {
      const Face& face = mesh.face(use.face);
      const ElementId other = use.reversed ? face.front : face.back;
      if (!other.valid() || seen.count(other.value)) continue;
      bool holds = false;
      for (std::size_t k = 0; k < face.numLoops() && !holds; ++k) {
        const auto loop = face.loop(k);
        for (std::size_t i = 0; i < loop.size() && !holds; ++i)
          holds = holdsEdge(loop[i], loop[(i + 1) % loop.size()]);
      }
      if (holds && seen.insert(other.value).second) queue.push_back(other);
    }
  }
  return out;
}

}  // namespace

OperationReport MeshEditor::refine(std::span<const ElementRefinement> elements,
                                   const RefineOptions& options) {
  if (!state_) throw std::logic_error("MeshEditor: used after release()");
  if (!(options.sliverFraction >= 0.0) || !std::isfinite(options.sliverFraction))
    throw std::invalid_argument("the sliver fraction must be finite and not negative");
  if (options.checkDegree < 1 || options.checkDegree > 3)
    throw std::invalid_argument("the validation degree must be 1, 2 or 3");
  std::unordered_set<std::uint32_t> listed;
  for (const ElementRefinement& r : elements) {
    if (!r.element.valid() || r.element.index() >= state_->mesh.numElements())
      throw std::invalid_argument("refine: element id " + std::to_string(r.element.value) +
                                  " is not in the mesh");
    if (!listed.insert(r.element.value).second)
      throw std::invalid_argument("refine: element " + std::to_string(r.element.value) +
                                  " is listed twice");
    if (r.planes.empty() || r.planes.size() > 3)
      throw std::invalid_argument("refine: an element is split by 1 to 3 planes");
  }
  const Stopwatch start;
  try {
    return refineInPlace(elements, options);
  } catch (const std::exception& e) {
    OperationReport report;
    report.op = "refine";
    report.check.level = options.checks;
    report.check.passed = false;
    report.check.failure = std::string("split: ") + e.what();
    report.seconds = start.seconds();
    return report;
  }
}

OperationReport MeshEditor::refineInPlace(std::span<const ElementRefinement> elements,
                                          const RefineOptions& options) {
  const Stopwatch start;
  State& s = *state_;
  OperationReport report;
  report.op = "refine";
  report.facesReintegrated += raiseMomentDegree(2 * options.checkDegree);
  const double volumeBefore = s.volume;
  Edit edit(s.mesh, *s.moments, s.grid);

  // The pieces of each listed element so far, and the volume its slivers are measured against.
  std::vector<std::vector<ElementId>> pieces(elements.size());
  std::vector<double> sliverVolume(elements.size());
  for (std::size_t i = 0; i < elements.size(); ++i) {
    pieces[i] = {elements[i].element};
    sliverVolume[i] = options.sliverFraction * s.moments->volume(elements[i].element) /
                      std::ldexp(1.0, static_cast<int>(elements[i].planes.size()));
  }
  std::unordered_set<std::uint32_t> split;  // listed elements some plane divided
  for (std::size_t round = 0; round < 3; ++round) {
    // The pieces each plane splits this round, with the listed element they come from.
    std::map<std::uint32_t, std::vector<std::pair<ElementId, std::size_t>>> byPlane;
    for (std::size_t i = 0; i < elements.size(); ++i) {
      if (elements[i].planes.size() <= round) continue;
      const std::uint32_t id = planeIdOf(s, elements[i].planes[round]);
      for (ElementId e : pieces[i]) byPlane[id].emplace_back(e, i);
      pieces[i].clear();
    }
    for (auto& [planeId, members] : byPlane) {
      Blade blade;
      static_cast<Plane&>(blade) = s.planes[planeId];
      s.vertexPlane.resize(s.mesh.numVertices());
      const std::size_t oldVertices = s.mesh.numVertices();
      VertexSides sides(s.mesh, blade, s.vertexPlane, planeId);
      std::vector<ElementId> crossed;
      for (const auto& [e, i] : members) {
        const auto [lo, hi] = sides.range(e);
        if (lo < 0 && hi > 0)
          crossed.push_back(e);
        else
          pieces[i].push_back(e);  // the plane misses this piece
      }
      if (crossed.empty()) continue;
      Splitter splitter(edit, sides, blade, s.vertexPlane, planeId);
      splitter.coupleCaps();
      splitter.setElements(crossed);
      std::unordered_map<std::uint32_t, std::size_t> itemOf;
      for (const auto& [e, i] : members) itemOf.emplace(e.value, i);
      std::vector<std::pair<ElementId, std::pair<Piece, Piece>>> toSplit;
      for (ElementId e : crossed) {
        auto caps = splitter.caps(e);
        if (caps.first.empty() || caps.second.empty()) {
          pieces[itemOf.at(e.value)].push_back(e);  // within round-off of the plane: whole
          continue;
        }
        toSplit.emplace_back(e, std::move(caps));
      }
      std::vector<ElementId> made;
      for (auto& [e, caps] : toSplit) {
        const std::size_t i = itemOf.at(e.value);
        split.insert(elements[i].element.value);
        for (const auto& [piece, side] : splitter.splitElement(e, caps)) {
          pieces[i].push_back(piece);
          made.push_back(piece);
        }
      }
      report.piecesCreated += made.size();
      attachSplitFaceParts(edit, splitter);
      const EdgePoints points = splitter.edgePoints();
      tagEdgePoints(s, points, oldVertices);
      insertEdgePoints(edit, elementsAroundEdges(s.mesh, made, points), points);
    }
  }
  report.elementsSplit = split.size();
  report.facesReintegrated += edit.updateMoments();

  // Slivers among each element's pieces, measured against that element's share per piece.
  double threshold = 0.0;
  if (options.sliverFraction > 0.0) {
    for (std::size_t i = 0; i < elements.size(); ++i) {
      if (pieces[i].size() < 2) continue;
      std::vector<ElementId> alive;
      for (ElementId e : pieces[i])
        if (!s.mesh.element(e).faces.empty()) alive.push_back(e);
      OperationReport merged;
      mergeSliverPieces(edit, std::move(alive), sliverVolume[i], merged);
      report.slivers += merged.slivers;
      report.sliversMerged += merged.sliversMerged;
      report.isolatedSlivers += merged.isolatedSlivers;
      threshold = std::max(threshold, sliverVolume[i]);
    }
  }
  report.sliverThreshold = threshold;
  report.facesReintegrated += edit.updateMoments();
  finishOperation(s, edit, volumeBefore, options.checks, options.checkDegree, threshold, report);
  report.seconds = start.seconds();
  return report;
}

OperationReport MeshEditor::coarsen(std::span<const std::vector<ElementId>> groups,
                                    CheckLevel checks, int checkDegree) {
  if (!state_) throw std::logic_error("MeshEditor: used after release()");
  if (checkDegree < 1 || checkDegree > 3)
    throw std::invalid_argument("the validation degree must be 1, 2 or 3");
  State& s = *state_;
  std::unordered_set<std::uint32_t> listed;
  for (const std::vector<ElementId>& group : groups) {
    if (group.size() < 2)
      throw std::invalid_argument("coarsen: a group needs two elements or more");
    for (ElementId e : group) {
      if (!e.valid() || e.index() >= s.mesh.numElements())
        throw std::invalid_argument("coarsen: element id " + std::to_string(e.value) +
                                    " is not in the mesh");
      if (!listed.insert(e.value).second)
        throw std::invalid_argument("coarsen: element " + std::to_string(e.value) +
                                    " is listed twice");
    }
  }
  const Stopwatch start;
  OperationReport report;
  report.op = "coarsen";
  report.facesReintegrated += raiseMomentDegree(2 * checkDegree);
  const double volumeBefore = s.volume;
  Edit edit(s.mesh, *s.moments, s.grid);
  for (const std::vector<ElementId>& group : groups)
    for (std::size_t i = 1; i < group.size(); ++i) edit.merge(group[i], group[0]);
  report.elementsSplit = 0;
  report.facesReintegrated += edit.updateMoments();
  finishOperation(s, edit, volumeBefore, checks, checkDegree, 0.0, report);
  report.seconds = start.seconds();
  return report;
}

}  // namespace polydg
