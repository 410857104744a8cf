#include "edit.h"

#include <algorithm>
#include <unordered_set>

namespace polydg::cut_detail {

void reversedLoops(const Face& face, std::vector<VertexId>& vertices,
                   std::vector<std::uint32_t>& loopEnd) {
  vertices.assign(face.vertices.begin(), face.vertices.end());
  loopEnd.assign(face.loopEnd.begin(), face.loopEnd.end());
  for (std::size_t k = 0; k < loopEnd.size(); ++k) {
    const std::size_t begin = k == 0 ? 0 : loopEnd[k - 1];
    std::reverse(vertices.begin() + begin + 1, vertices.begin() + loopEnd[k]);
  }
}

PiecePolygon reversedPolygon(const PiecePolygon& p) {
  PiecePolygon r = p;
  for (std::size_t k = 0; k < p.numLoops(); ++k)
    std::reverse(r.vertices.begin() + p.loopBegin(k), r.vertices.begin() + p.loopEnd[k]);
  return r;
}

void decouple(Edit& edit, FaceId f) {
  PolyMesh& mesh = edit.mesh();
  const Face& face = mesh.face(f);
  const ElementId front = face.front, back = face.back;
  edit.touch(front);
  edit.touch(back);
  std::vector<VertexId> vertices;
  std::vector<std::uint32_t> loopEnd;
  reversedLoops(face, vertices, loopEnd);
  const FaceId copy = edit.addFace(vertices, loopEnd, FaceOrigin::Cut);
  mesh.detachFace(back, f);
  mesh.attachFace(back, {copy, false});
  mesh.setOrigin(f, FaceOrigin::Cut);
}

void mergeSliverPieces(Edit& edit, std::vector<ElementId> candidates, double threshold,
                       OperationReport& report) {
  report.sliverThreshold = threshold;
  PolyMesh& mesh = edit.mesh();
  MomentCache& cache = edit.cache();
  std::unordered_set<std::uint32_t> dead;
  std::sort(candidates.begin(), candidates.end(), [&](ElementId a, ElementId b) {
    const double va = cache.volume(a), vb = cache.volume(b);
    return va != vb ? va < vb : a < b;
  });
  for (ElementId e : candidates) report.slivers += cache.volume(e) < threshold;
  for (ElementId g : candidates) {
    if (dead.count(g.value)) continue;
    bool merged = false;
    while (cache.volume(g) < threshold) {
      std::map<std::uint32_t, double> shared;
      for (const FaceUse& use : mesh.element(g).faces) {
        const Face& face = mesh.face(use.face);
        if (!face.front.valid() || !face.back.valid()) continue;
        const ElementId other = use.reversed ? face.front : face.back;
        shared[other.value] += cache.area(use.face);
      }
      if (shared.empty()) {
        if (!merged) ++report.isolatedSlivers;
        break;
      }
      const auto best = std::max_element(shared.begin(), shared.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      const ElementId target(best->first);
      edit.merge(g, target);
      dead.insert(g.value);
      cache.update();  // the target's moments from its faces (no face is integrated)
      ++report.sliversMerged;
      merged = true;
      g = target;
    }
  }
}

}  // namespace polydg::cut_detail
