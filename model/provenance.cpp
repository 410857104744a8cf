#include "polydg/model/provenance.h"

#include <cmath>

namespace polydg {

namespace {
constexpr const char* kCellSize = "polydg_cell_size";
constexpr const char* kReferenceVolume = "polydg_reference_volume";
constexpr const char* kSliverFraction = "polydg_sliver_fraction";
constexpr const char* kReference = "polydg_reference";
constexpr const char* kSource = "polydg_source";
constexpr const char* kCutPlanes = "polydg_cut_planes";  // nx, ny, nz, d per cut

/// The single number stored under `name`, if there is one.
std::optional<double> number(const VtuFieldData& data, const char* name) {
  const auto it = data.numbers.find(name);
  if (it == data.numbers.end() || it->second.size() != 1) return std::nullopt;
  return it->second.front();
}
}  // namespace

VtuFieldData provenanceFieldData(const Provenance& p) {
  VtuFieldData data;
  data.numbers[kCellSize] = {p.cellSize};
  data.numbers[kReferenceVolume] = {p.referenceVolume};
  data.numbers[kSliverFraction] = {p.sliverFraction};
  data.strings[kReference] =
      p.referenceKind == ReferenceKind::GridCell ? "grid_cell" : "median_element";
  data.strings[kSource] = p.source;
  if (!p.cuts.empty()) {
    std::vector<double>& planes = data.numbers[kCutPlanes];
    for (const Plane& c : p.cuts)
      planes.insert(planes.end(), {c.normal.x(), c.normal.y(), c.normal.z(), c.offset});
  }
  return data;
}

std::optional<Provenance> provenanceFromFieldData(const VtuFieldData& data) {
  const auto cell = number(data, kCellSize);
  const auto volume = number(data, kReferenceVolume);
  const auto fraction = number(data, kSliverFraction);
  const auto kind = data.strings.find(kReference);
  if (!cell || !volume || !fraction || kind == data.strings.end()) return std::nullopt;
  if (!(std::isfinite(*cell) && *cell >= 0.0) || !(std::isfinite(*volume) && *volume > 0.0) ||
      !(*fraction >= 0.0 && *fraction <= 1.0))
    return std::nullopt;
  Provenance p;
  if (kind->second == "grid_cell")
    p.referenceKind = ReferenceKind::GridCell;
  else if (kind->second == "median_element")
    p.referenceKind = ReferenceKind::MedianElement;
  else
    return std::nullopt;
  p.cellSize = *cell;
  p.referenceVolume = *volume;
  p.sliverFraction = *fraction;
  const auto source = data.strings.find(kSource);
  if (source != data.strings.end()) p.source = source->second;
  // The cuts are labels for export's patches: a malformed list is dropped, not refused.
  const auto planes = data.numbers.find(kCutPlanes);
  if (planes != data.numbers.end() && planes->second.size() % 4 == 0) {
    try {
      for (std::size_t k = 0; k < planes->second.size(); k += 4) {
        const double* c = planes->second.data() + k;
        p.cuts.push_back(Plane::make(Vec3(c[0], c[1], c[2]), c[3]));
      }
    } catch (const std::invalid_argument&) {
      p.cuts.clear();
    }
  }
  return p;
}

}  // namespace polydg
