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
#include <tbb/enumerable_thread_specific.h>
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

/// The elements that are not flagged as whole cells, in increasing order.
std::vector<std::uint32_t> unflagged(std::size_t n, const std::vector<char>& wholeCells) {
  std::vector<std::uint32_t> out;
  out.reserve(wholeCells.empty() ? n : n - std::count(wholeCells.begin(), wholeCells.end(), 1));
  for (std::uint32_t e = 0; e < n; ++e)
    if (!flagged(wholeCells, e)) out.push_back(e);
  return out;
}

/// Sets of elements joined by a merge, kept for the elements that take part in it: those listed
/// at the start and those taken later; every other element is a set of its own. The sets and
/// their representatives are those UnionFind over all elements gives for the same unions, with
/// 4 bytes per element instead of a set's state and a group's figures: slicing's whole cells,
/// most of a large mesh, take part only when a group joins one.
class ElementSets {
 public:
  static constexpr std::uint32_t kNone = ~std::uint32_t(0);

  /// `listed`: distinct elements of a mesh of n.
  ElementSets(std::size_t n, std::vector<std::uint32_t> listed)
      : element_(std::move(listed)), slot_(n, kNone), sets_(element_.size()) {
    for (std::uint32_t s = 0; s < element_.size(); ++s) slot_[element_[s]] = s;
  }

  std::size_t slots() const { return element_.size(); }
  std::uint32_t element(std::uint32_t slot) const { return element_[slot]; }
  /// Element e's slot, or kNone if it takes no part.
  std::uint32_t slot(std::uint32_t e) const { return slot_[e]; }
  /// Element e's slot, made (a set of its own) if it has none.
  std::uint32_t take(std::uint32_t e) {
    if (slot_[e] == kNone) {
      slot_[e] = sets_.add();
      element_.push_back(e);
    }
    return slot_[e];
  }
  /// The representative element of e's set.
  std::uint32_t find(std::uint32_t e) {
    const std::uint32_t s = slot_[e];
    return s == kNone ? e : element_[sets_.find(s)];
  }
  std::uint32_t findSlot(std::uint32_t s) { return sets_.find(s); }
  /// Joins a's set to b's; b's representative represents the union.
  void unite(std::uint32_t a, std::uint32_t b) { sets_.unite(take(a), take(b)); }

  /// Per element, the label of its set: 0 .. count-1 numbering the sets in order of their
  /// smallest element, or kDroppedElement for a set whose representative's slot `dropped`
  /// names. Returns count.
  template <class Dropped>
  std::size_t labels(std::vector<std::uint32_t>& out, Dropped&& dropped) {
    std::vector<std::uint32_t> labelOfRoot(slots(), kNone);
    out.resize(slot_.size());
    std::uint32_t count = 0;
    for (std::uint32_t e = 0; e < slot_.size(); ++e) {
      if (slot_[e] == kNone) {
        out[e] = count++;
        continue;
      }
      const std::uint32_t root = sets_.find(slot_[e]);
      if (dropped(root)) {
        out[e] = kDroppedElement;
        continue;
      }
      if (labelOfRoot[root] == kNone) labelOfRoot[root] = count++;
      out[e] = labelOfRoot[root];
    }
    return count;
  }

 private:
  std::vector<std::uint32_t> element_;  ///< per slot: the listed elements, then those taken
  std::vector<std::uint32_t> slot_;     ///< per element: its slot, or kNone
  UnionFind sets_;                      ///< over slots
};

/// Adds to shared[h] the area of the interior faces between group g (its `members`) and each
/// other group h.
void addSharedAreas(const PolyMesh& mesh, ElementSets& sets, std::uint32_t g,
                    const std::vector<std::uint32_t>& members,
                    std::map<std::uint32_t, double>& shared) {
  for (std::uint32_t m : members)
    for (const FaceUse& use : mesh.element(ElementId(m)).faces) {
      const Face& face = mesh.face(use.face);
      if (!face.front.valid() || !face.back.valid()) continue;
      const std::uint32_t other = sets.find((use.reversed ? face.front : face.back).value);
      if (other != g) shared[other] += areaVector(mesh, use.face).norm();
    }
}

/// Groups of elements merged by mergeSlivers(): a group's volume and area are kept at its
/// representative's slot. NaN marks a whole cell no sliver has joined yet, measured when one
/// does.
class SliverGroups {
 public:
  SliverGroups(const PolyMesh& mesh, const std::vector<std::uint32_t>& candidates)
      : mesh_(mesh),
        sets_(mesh.numElements(), candidates),
        volume_(candidates.size()),
        area_(candidates.size()),
        members_(candidates.size()) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size(), 512),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i)
                          std::tie(volume_[i], area_[i]) =
                              volumeAndArea(mesh, ElementId(candidates[i]));
                      });
  }
  std::optional<std::uint32_t> group(std::uint32_t e) { return sets_.find(e); }
  double volume(std::uint32_t g) { return measured(g).first; }
  double area(std::uint32_t g) { return measured(g).second; }
  void sharedAreas(std::uint32_t g, std::map<std::uint32_t, double>& shared) {
    addSharedAreas(mesh_, sets_, g, membersAt(slotOf(g)), shared);
  }
  std::uint32_t merge(std::uint32_t g, std::uint32_t target, double sharedArea) {
    measured(target);
    const std::uint32_t from = slotOf(g), into = slotOf(target);
    sets_.unite(g, target);  // target stays the representative
    volume_[into] += volume_[from];
    area_[into] += area_[from] - 2.0 * sharedArea;
    std::vector<std::uint32_t>& intoMembers = membersAt(into);
    const std::vector<std::uint32_t>& fromMembers = membersAt(from);
    intoMembers.insert(intoMembers.end(), fromMembers.begin(), fromMembers.end());
    members_[from].clear();
    return target;
  }
  std::size_t labels(std::vector<std::uint32_t>& out) {
    return sets_.labels(out, [](std::uint32_t) { return false; });
  }

 private:
  /// Element e's slot, made unmeasured if it had none.
  std::uint32_t slotOf(std::uint32_t e) {
    const std::uint32_t s = sets_.take(e);
    if (s == volume_.size()) {
      volume_.push_back(std::numeric_limits<double>::quiet_NaN());
      area_.push_back(std::numeric_limits<double>::quiet_NaN());
      members_.emplace_back();
    }
    return s;
  }
  /// Group g's volume and area, measured first if g is a whole cell no sliver joined yet.
  std::pair<double, double> measured(std::uint32_t g) {
    const std::uint32_t s = slotOf(g);
    if (std::isnan(volume_[s])) std::tie(volume_[s], area_[s]) = volumeAndArea(mesh_, ElementId(g));
    return {volume_[s], area_[s]};
  }
  /// The members of the group represented at slot s, listed once it took in another (a group
  /// never merged is its element alone).
  std::vector<std::uint32_t>& membersAt(std::uint32_t s) {
    std::vector<std::uint32_t>& members = members_[s];
    if (members.empty()) members.push_back(sets_.element(s));
    return members;
  }

  const PolyMesh& mesh_;
  ElementSets sets_;
  std::vector<double> volume_, area_;  // per slot
  std::vector<std::vector<std::uint32_t>> members_;
};

}  // namespace

PolyMesh mergeSlivers(PolyMesh mesh, double volumeThreshold, SliverMergeReport* report,
                      const std::vector<char>& wholeCells) {
  const std::size_t n = mesh.numElements();
  if (!wholeCells.empty() && wholeCells.size() != n)
    throw std::invalid_argument("mergeSlivers: one whole-cell flag per element is needed");
  // Volumes and areas of the elements that may be slivers; a whole cell's are measured when a
  // sliver joins it. (Face areas are measured where they are read: most faces never are.)
  const std::vector<std::uint32_t> candidates = unflagged(n, wholeCells);
  SliverGroups groups(mesh, candidates);
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
/// its representative's slot. The elements listed at the start are those that may be
/// degenerate; a whole cell takes part (measured) when another group joins it.
class DegenerateGroups {
 public:
  DegenerateGroups(const PolyMesh& mesh, const std::vector<std::uint32_t>& candidates)
      : mesh_(mesh), sets_(mesh.numElements(), candidates) {}

  ElementSets& sets() { return sets_; }

  /// Starts the volumes from the listed elements' volumes (per slot) and the current sets.
  void gather(const std::vector<double>& elementVolume) {
    volume_.assign(elementVolume.size(), 0.0);
    for (std::uint32_t s = 0; s < elementVolume.size(); ++s)
      volume_[sets_.findSlot(s)] += elementVolume[s];
  }

  /// Joins group g (a representative) to its neighbours until its volume is positive; false if
  /// it has no neighbour left before that.
  bool joinUntilPositive(std::uint32_t g, std::size_t& merges) {
    listMembers();
    std::map<std::uint32_t, double> shared;
    while (!(volume(g) > 0.0)) {
      shared.clear();
      addSharedAreas(mesh_, sets_, g, members_[sets_.slot(g)], shared);
      if (shared.empty()) return false;
      const auto best = std::max_element(shared.begin(), shared.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
      const std::uint32_t target = best->first;
      const std::uint32_t into = slotOf(target), from = sets_.slot(g);
      sets_.unite(g, target);  // target stays the representative
      volume_[into] += volume_[from];
      members_[into].insert(members_[into].end(), members_[from].begin(), members_[from].end());
      members_[from].clear();
      ++merges;
      g = target;
    }
    return true;
  }

  /// Group g's volume (g a representative); a whole cell's if g takes no part.
  double volume(std::uint32_t g) {
    const std::uint32_t s = sets_.slot(g);
    return s == ElementSets::kNone ? std::numeric_limits<double>::infinity() : volume_[s];
  }

 private:
  /// Lists each group's members, the first time a group has to join others: usually no group
  /// does, and a list per element would be many small allocations for nothing.
  void listMembers() {
    if (!members_.empty()) return;
    members_.resize(sets_.slots());
    for (std::uint32_t s = 0; s < sets_.slots(); ++s)
      members_[sets_.findSlot(s)].push_back(sets_.element(s));
  }
  /// Element e's slot; a whole cell that takes none yet is measured, a group of its own.
  std::uint32_t slotOf(std::uint32_t e) {
    const std::uint32_t s = sets_.take(e);
    if (s == volume_.size()) {
      volume_.push_back(signedVolume(mesh_, ElementId(e)));
      members_.push_back({e});
    }
    return s;
  }

  const PolyMesh& mesh_;
  ElementSets sets_;
  std::vector<double> volume_;  // per slot
  std::vector<std::vector<std::uint32_t>> members_;
};

/// The interior faces between two of `candidates` that are degenerate, in increasing order:
/// each found from the element in front of it.
std::vector<std::uint32_t> degenerateFaces(const PolyMesh& mesh,
                                           const std::vector<std::uint32_t>& candidates,
                                           const std::vector<char>& wholeCells) {
  tbb::enumerable_thread_specific<std::vector<std::uint32_t>> found;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, candidates.size(), 1024),
      [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<std::uint32_t>& out = found.local();
        for (std::size_t i = r.begin(); i != r.end(); ++i)
          for (const FaceUse& use : mesh.element(ElementId(candidates[i])).faces) {
            const Face& face = mesh.face(use.face);
            if (use.reversed || !face.back.valid() || flagged(wholeCells, face.back.index()))
              continue;
            if (isDegenerateFace(mesh, use.face)) out.push_back(use.face.value);
          }
      });
  std::vector<std::uint32_t> faces;
  for (const std::vector<std::uint32_t>& part : found)
    faces.insert(faces.end(), part.begin(), part.end());
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

}  // namespace

PolyMesh mergeDegenerateElements(PolyMesh mesh, DegenerateMergeReport* report,
                                 const std::vector<char>& wholeCells) {
  const std::size_t n = mesh.numElements();
  if (!wholeCells.empty() && wholeCells.size() != n)
    throw std::invalid_argument(
        "mergeDegenerateElements: one whole-cell flag per element is needed");
  // A whole cell's faces are grid quadrilaterals and its volume is positive: neither is
  // measured, and it takes part only if a group joins it.
  const std::vector<std::uint32_t> candidates = unflagged(n, wholeCells);
  const std::vector<std::uint32_t> degenerate = degenerateFaces(mesh, candidates, wholeCells);
  std::vector<double> volume(candidates.size());
  tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t i) {
    volume[i] = signedVolume(mesh, ElementId(candidates[i]));
  });
  DegenerateMergeReport r;
  DegenerateGroups groups(mesh, candidates);
  ElementSets& sets = groups.sets();
  for (const std::uint32_t f : degenerate) {
    const Face& face = mesh.face(FaceId(f));
    if (sets.find(face.front.value) == sets.find(face.back.value)) continue;
    sets.unite(face.front.value, face.back.value);
    ++r.merged;
  }
  groups.gather(volume);
  // Only a listed element can be a group of no volume: a whole cell is one of its own, or the
  // representative of a group that joined it until its volume was positive.
  std::vector<char> dropped;  // per slot
  for (std::uint32_t s = 0; s < candidates.size(); ++s) {
    const std::uint32_t e = candidates[s];
    if (sets.find(e) == e && !(groups.volume(e) > 0.0) && !groups.joinUntilPositive(e, r.merged)) {
      dropped.resize(sets.slots(), 0);
      dropped[sets.findSlot(sets.slot(e))] = 1;
    }
  }
  dropped.resize(sets.slots(), 0);
  for (std::uint32_t s = 0; s < sets.slots(); ++s) r.dropped += dropped[sets.findSlot(s)];
  if (r.merged == 0 && r.dropped == 0) {
    r.group.resize(n);
    std::iota(r.group.begin(), r.group.end(), 0u);
    if (report) *report = std::move(r);
    return mesh;
  }
  // Groups in order of their first element; dropped ones left out.
  const std::size_t count =
      sets.labels(r.group, [&](std::uint32_t root) { return dropped[root] != 0; });
  mesh.mergeElementGroups(r.group, count);
  if (report) *report = std::move(r);
  return mesh;
}

}  // namespace polydg
