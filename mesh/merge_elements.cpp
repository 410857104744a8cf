#include "polydg/mesh/merge_elements.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <tuple>

#include "polydg/mesh/geometry.h"
#include "polydg/mesh/geometry_checks.h"
#include "util/union_find.h"

#include <tbb/blocked_range.h>
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

namespace {

/// Element e's volume (signedVolume, to the bit) and surface area (its faces' area norms), in
/// one pass over its faces.
std::pair<double, double> volumeAndArea(const PolyMesh& mesh, ElementId e) {
  const Vec3 o = elementReferencePoint(mesh, e);
  double threeVolume = 0.0, surface = 0.0;
  for (const FaceUse& use : mesh.element(e).faces) {
    const Vec3 a = areaVector(mesh, use.face);
    const double h = a.dot(faceReferencePoint(mesh, use.face) - o);
    threeVolume += use.reversed ? -h : h;
    surface += a.norm();
  }
  return {threeVolume / 3.0, surface};
}

bool flagged(const std::vector<char>& flags, std::size_t e) { return !flags.empty() && flags[e]; }

}  // namespace

PolyMesh mergeSlivers(PolyMesh mesh, double volumeThreshold, SliverMergeReport* report,
                      const std::vector<char>& wholeCells) {
  const std::size_t n = mesh.numElements();
  if (!wholeCells.empty() && wholeCells.size() != n)
    throw std::invalid_argument("mergeSlivers: one whole-cell flag per element is needed");
  // Volumes and areas of the elements that may be slivers; a whole cell's are measured when a
  // sliver joins it. (Face areas are measured where they are read: most faces never are.)
  constexpr double kUnmeasured = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> volume(n, kUnmeasured), area(n, kUnmeasured);
  std::vector<std::uint32_t> candidates;
  candidates.reserve(n);
  for (std::uint32_t e = 0; e < n; ++e)
    if (!flagged(wholeCells, e)) candidates.push_back(e);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size(), 512),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const std::uint32_t e = candidates[i];
                        std::tie(volume[e], area[e]) = volumeAndArea(mesh, ElementId(e));
                      }
                    });

  // Groups of elements by union-find; a group's volume and area are kept at its representative.
  class Groups {
   public:
    Groups(const PolyMesh& mesh, std::vector<double> volume, std::vector<double> area)
        : mesh_(mesh),
          volume_(std::move(volume)),
          area_(std::move(area)),
          sets_(volume_.size()),
          members_(volume_.size()) {}
    std::optional<std::uint32_t> group(std::uint32_t e) { return sets_.find(e); }
    double volume(std::uint32_t g) { return measured(g).first; }
    double area(std::uint32_t g) { return measured(g).second; }
    void sharedAreas(std::uint32_t g, std::map<std::uint32_t, double>& shared) {
      for (std::uint32_t m : membersOf(g))
        for (const FaceUse& use : mesh_.element(ElementId(m)).faces) {
          const Face& face = mesh_.face(use.face);
          if (!face.front.valid() || !face.back.valid()) continue;
          const std::uint32_t other = sets_.find((use.reversed ? face.front : face.back).value);
          if (other != g) shared[other] += areaVector(mesh_, use.face).norm();
        }
    }
    std::uint32_t merge(std::uint32_t g, std::uint32_t target, double sharedArea) {
      measured(target);
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
    /// Group g's volume and area, measured first if g is a whole cell no sliver joined yet.
    std::pair<double, double> measured(std::uint32_t g) {
      if (std::isnan(volume_[g]))
        std::tie(volume_[g], area_[g]) = volumeAndArea(mesh_, ElementId(g));
      return {volume_[g], area_[g]};
    }
    // Members of each group that took in another (a group never merged is its element alone).
    std::vector<std::uint32_t>& membersOf(std::uint32_t g) {
      if (members_[g].empty()) members_[g].push_back(g);
      return members_[g];
    }
    const PolyMesh& mesh_;
    std::vector<double> volume_, area_;
    UnionFind sets_;
    std::vector<std::vector<std::uint32_t>> members_;
  };
  Groups groups(mesh, std::move(volume), std::move(area));
  const SliverMergeSummary counts = mergeSliverGroups(candidates, volumeThreshold, groups);

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
/// its representative. A volume of +infinity stands for a whole cell's, measured when another
/// group joins it.
class DegenerateGroups {
 public:
  explicit DegenerateGroups(const PolyMesh& mesh) : mesh_(mesh), sets_(mesh.numElements()) {}

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
          if (other != g) shared[other] += areaVector(mesh_, use.face).norm();
        }
      if (shared.empty()) return false;
      const auto best = std::max_element(shared.begin(), shared.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      const std::uint32_t target = best->first;
      // A whole cell (alone in its group until now) is measured.
      if (std::isinf(volume_[target])) volume_[target] = signedVolume(mesh_, ElementId(target));
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
  UnionFind sets_;
  std::vector<double> volume_;
  std::vector<std::vector<std::uint32_t>> members_;
};

}  // namespace

PolyMesh mergeDegenerateElements(PolyMesh mesh, DegenerateMergeReport* report,
                                 const std::vector<char>& wholeCells) {
  const std::size_t n = mesh.numElements(), nf = mesh.numFaces();
  if (!wholeCells.empty() && wholeCells.size() != n)
    throw std::invalid_argument(
        "mergeDegenerateElements: one whole-cell flag per element is needed");
  // A whole cell's faces are grid quadrilaterals and its volume is positive: neither is
  // measured.
  auto whole = [&](ElementId e) { return e.valid() && flagged(wholeCells, e.index()); };
  std::vector<char> degenerate(nf);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, nf, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t f = r.begin(); f != r.end(); ++f) {
          const Face& face = mesh.face(FaceId(f));
          degenerate[f] =
              !whole(face.front) && !whole(face.back) && isDegenerateFace(mesh, FaceId(f));
        }
      });
  std::vector<double> volume(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t e) {
    volume[e] = whole(ElementId(e)) ? std::numeric_limits<double>::infinity()
                                    : signedVolume(mesh, ElementId(e));
  });
  DegenerateMergeReport r;
  DegenerateGroups groups(mesh);
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
