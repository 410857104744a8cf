#include "edit.h"

#include <algorithm>
#include <optional>
#include <unordered_set>

#include "polydg/mesh/merge_elements.h"

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
  // The elements of the mesh being edited as the groups of mergeSliverGroups (the rule and the
  // merge slicing runs): a merged element is gone, its faces moved to the target.
  class Groups {
   public:
    explicit Groups(Edit& edit) : edit_(edit) {}
    std::optional<std::uint32_t> group(std::uint32_t e) const {
      return dead_.count(e) ? std::nullopt : std::optional<std::uint32_t>(e);
    }
    double volume(std::uint32_t g) const { return edit_.cache().volume(ElementId(g)); }
    double area(std::uint32_t g) const {
      double a = 0.0;
      for (const FaceUse& use : edit_.mesh().element(ElementId(g)).faces)
        a += edit_.cache().area(use.face);
      return a;
    }
    void sharedAreas(std::uint32_t g, std::map<std::uint32_t, double>& shared) const {
      const PolyMesh& mesh = edit_.mesh();
      for (const FaceUse& use : mesh.element(ElementId(g)).faces) {
        const Face& face = mesh.face(use.face);
        if (!face.front.valid() || !face.back.valid()) continue;
        const ElementId other = use.reversed ? face.front : face.back;
        shared[other.value] += edit_.cache().area(use.face);
      }
    }
    std::uint32_t merge(std::uint32_t g, std::uint32_t target, double /*sharedArea*/) {
      edit_.merge(ElementId(g), ElementId(target));
      dead_.insert(g);
      edit_.cache().update();  // the target's moments from its faces (no face is integrated)
      return target;
    }

   private:
    Edit& edit_;
    std::unordered_set<std::uint32_t> dead_;
  };
  Groups groups(edit);
  std::vector<std::uint32_t> ids;
  ids.reserve(candidates.size());
  for (ElementId e : candidates) ids.push_back(e.value);
  const SliverMergeSummary counts = mergeSliverGroups(ids, threshold, groups);
  report.sliverThreshold = threshold;
  report.slivers += counts.slivers;
  report.sliversMerged += counts.merged;
  report.isolatedSlivers += counts.isolated;
}

}  // namespace polydg::cut_detail
