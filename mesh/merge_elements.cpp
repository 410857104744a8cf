#include "polydg/mesh/merge_elements.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"
#include "util/resident.h"
#include "util/union_find.h"

#include <tbb/parallel_for.h>

namespace polydg {

PolyMesh mergeElements(const PolyMesh& mesh, const std::vector<std::uint32_t>& group,
                       std::size_t groups) {
  if (group.size() != mesh.numElements())
    throw std::invalid_argument("mergeElements: one group per element is needed");
  PolyMesh out = mesh;
  out.mergeElementGroups(group, groups);
  return out;
}

double sliverSize(double volume, double area) {
  return std::min(std::cbrt(volume), 6.0 * volume / area);
}

bool isSliver(double volume, double area, double volumeThreshold) {
  const double size = sliverSize(volume, area);
  return size * size * size < volumeThreshold;
}

PolyMesh mergeSlivers(PolyMesh mesh, double volumeThreshold, SliverMergeReport* report) {
  const std::size_t n = mesh.numElements();
  // Each face's area vector once; element volumes from them (signed cones from the element's
  // reference point) and element surface areas.
  std::vector<Vec3> areaVectors = residentVector<Vec3>(mesh.numFaces());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.numFaces(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t f = r.begin(); f != r.end(); ++f)
                        areaVectors[f] = areaVector(mesh, FaceId(f));
                    });
  auto faceArea = [&](std::size_t f) { return areaVectors[f].norm(); };
  std::vector<double> volume(n), area(n);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, n, 512), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t e = r.begin(); e != r.end(); ++e) {
          const Vec3 o = elementReferencePoint(mesh, ElementId(e));
          double threeVolume = 0.0, surface = 0.0;
          for (const FaceUse& use : mesh.element(ElementId(e)).faces) {
            const double h =
                areaVectors[use.face.index()].dot(faceReferencePoint(mesh, use.face) - o);
            threeVolume += use.reversed ? -h : h;
            surface += faceArea(use.face.index());
          }
          volume[e] = threeVolume / 3.0;
          area[e] = surface;
        }
      });

  // Groups of elements by union-find; a group's volume and area are kept at its representative.
  class Groups {
   public:
    Groups(const PolyMesh& mesh, const std::vector<Vec3>& areaVectors, std::vector<double> volume,
           std::vector<double> area)
        : mesh_(mesh),
          areaVectors_(areaVectors),
          volume_(std::move(volume)),
          area_(std::move(area)),
          sets_(volume_.size()),
          members_(volume_.size()) {}
    std::optional<std::uint32_t> group(std::uint32_t e) { return sets_.find(e); }
    double volume(std::uint32_t g) const { return volume_[g]; }
    double area(std::uint32_t g) const { return area_[g]; }
    void sharedAreas(std::uint32_t g, std::map<std::uint32_t, double>& shared) {
      for (std::uint32_t m : membersOf(g))
        for (const FaceUse& use : mesh_.element(ElementId(m)).faces) {
          const Face& face = mesh_.face(use.face);
          if (!face.front.valid() || !face.back.valid()) continue;
          const std::uint32_t other = sets_.find((use.reversed ? face.front : face.back).value);
          if (other != g) shared[other] += areaVectors_[use.face.index()].norm();
        }
    }
    std::uint32_t merge(std::uint32_t g, std::uint32_t target, double sharedArea) {
      sets_.unite(g, target);  // target stays the representative
      volume_[target] += volume_[g];
      area_[target] += area_[g] - 2.0 * sharedArea;
      std::vector<std::uint32_t>& into = membersOf(target);
      const std::vector<std::uint32_t>& from = membersOf(g);
      into.insert(into.end(), from.begin(), from.end());
      members_[g].clear();
      return target;
    }
    std::size_t labels(std::vector<std::uint32_t>& out) { return sets_.labels(out); }

   private:
    // Members of each group that took in another (a group never merged is its element alone).
    std::vector<std::uint32_t>& membersOf(std::uint32_t g) {
      if (members_[g].empty()) members_[g].push_back(g);
      return members_[g];
    }
    const PolyMesh& mesh_;
    const std::vector<Vec3>& areaVectors_;
    std::vector<double> volume_, area_;
    UnionFind sets_;
    std::vector<std::vector<std::uint32_t>> members_;
  };
  Groups groups(mesh, areaVectors, std::move(volume), std::move(area));
  std::vector<std::uint32_t> all(n);
  std::iota(all.begin(), all.end(), std::uint32_t(0));
  const SliverMergeSummary counts = mergeSliverGroups(all, volumeThreshold, groups);

  SliverMergeReport r;
  r.threshold = counts.threshold;
  r.slivers = counts.slivers;
  r.merged = counts.merged;
  r.isolated = counts.isolated;
  // Number the groups in order of their first element.
  const std::size_t count = groups.labels(r.group);
  if (count != n) mesh.mergeElementGroups(r.group, count);
  if (report) *report = std::move(r);
  return mesh;
}

namespace {

/// Groups of elements joined by mergeDegenerateElements(): each group's volume and members at
/// its representative.
class DegenerateGroups {
 public:
  DegenerateGroups(const PolyMesh& mesh, const std::vector<double>& faceArea)
      : mesh_(mesh), faceArea_(faceArea), sets_(mesh.numElements()) {}

  UnionFind& sets() { return sets_; }

  /// Starts the volumes from the elements' volumes and the current sets.
  void gather(const std::vector<double>& elementVolume) {
    volume_.assign(elementVolume.size(), 0.0);
    for (std::uint32_t e = 0; e < elementVolume.size(); ++e)
      volume_[sets_.find(e)] += elementVolume[e];
  }

  /// Joins group g (a representative) to its neighbours until its volume is positive; false if
  /// it has no neighbour left before that.
  bool joinUntilPositive(std::uint32_t g, std::size_t& merges) {
    listMembers();
    std::map<std::uint32_t, double> shared;
    while (!(volume_[g] > 0.0)) {
      shared.clear();
      for (std::uint32_t m : members_[g])
        for (const FaceUse& use : mesh_.element(ElementId(m)).faces) {
          const Face& face = mesh_.face(use.face);
          if (!face.front.valid() || !face.back.valid()) continue;
          const std::uint32_t other = sets_.find((use.reversed ? face.front : face.back).value);
          if (other != g) shared[other] += faceArea_[use.face.index()];
        }
      if (shared.empty()) return false;
      const auto best = std::max_element(shared.begin(), shared.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      const std::uint32_t target = best->first;
      sets_.unite(g, target);  // target stays the representative
      volume_[target] += volume_[g];
      members_[target].insert(members_[target].end(), members_[g].begin(), members_[g].end());
      members_[g].clear();
      ++merges;
      g = target;
    }
    return true;
  }

  double volume(std::uint32_t g) const { return volume_[g]; }

 private:
  /// Lists each group's members, the first time a group has to join others: usually no group
  /// does, and a list per element would be a million small allocations for nothing.
  void listMembers() {
    if (!members_.empty()) return;
    members_.resize(volume_.size());
    for (std::uint32_t e = 0; e < volume_.size(); ++e) members_[sets_.find(e)].push_back(e);
  }

  const PolyMesh& mesh_;
  const std::vector<double>& faceArea_;
  UnionFind sets_;
  std::vector<double> volume_;
  std::vector<std::vector<std::uint32_t>> members_;
};

}  // namespace

PolyMesh mergeDegenerateElements(PolyMesh mesh, DegenerateMergeReport* report) {
  const std::size_t n = mesh.numElements(), nf = mesh.numFaces();
  std::vector<double> faceArea(nf);
  std::vector<char> degenerate(nf);
  tbb::parallel_for(std::size_t(0), nf, [&](std::size_t f) {
    const Vec3 a = areaVector(mesh, FaceId(f));
    faceArea[f] = a.norm();
    degenerate[f] = isDegenerateFace(mesh, FaceId(f), a);
  });
  std::vector<double> volume(n);
  tbb::parallel_for(std::size_t(0), n,
                    [&](std::size_t e) { volume[e] = signedVolume(mesh, ElementId(e)); });
  DegenerateMergeReport r;
  DegenerateGroups groups(mesh, faceArea);
  UnionFind& sets = groups.sets();
  for (std::size_t f = 0; f < nf; ++f) {
    const Face& face = mesh.face(FaceId(f));
    if (!degenerate[f] || !face.front.valid() || !face.back.valid()) continue;
    if (sets.find(face.front.value) == sets.find(face.back.value)) continue;
    sets.unite(face.front.value, face.back.value);
    ++r.merged;
  }
  groups.gather(volume);
  std::vector<char> dropped(n, 0);
  for (std::uint32_t e = 0; e < n; ++e)
    if (sets.find(e) == e && !(groups.volume(e) > 0.0) && !groups.joinUntilPositive(e, r.merged))
      dropped[sets.find(e)] = 1;
  for (std::uint32_t e = 0; e < n; ++e) r.dropped += dropped[sets.find(e)];
  if (r.merged == 0 && r.dropped == 0) {
    r.group.resize(n);
    std::iota(r.group.begin(), r.group.end(), 0u);
    if (report) *report = std::move(r);
    return mesh;
  }
  // Groups in order of their first element; dropped ones left out.
  std::vector<std::uint32_t> label(n, kDroppedElement);
  r.group.assign(n, kDroppedElement);
  std::uint32_t count = 0;
  for (std::uint32_t e = 0; e < n; ++e) {
    const std::uint32_t g = sets.find(e);
    if (dropped[g]) continue;
    if (label[g] == kDroppedElement) label[g] = count++;
    r.group[e] = label[g];
  }
  mesh.mergeElementGroups(r.group, count);
  if (report) *report = std::move(r);
  return mesh;
}

}  // namespace polydg
