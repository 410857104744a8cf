#include "polydg/mesh/meshing.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <optional>
#include <sstream>
#include <string>

#include "mesh/surface_repair.h"
#include "mesh/whole_cells.h"
#include "util/format.h"
#include "util/held_memory.h"
#include "util/stopwatch.h"

namespace polydg {

namespace {

class PhaseTimer {
 public:
  explicit PhaseTimer(std::vector<std::pair<std::string, double>>& timings) : timings_(timings) {}
  void done(const std::string& phase) {
    timings_.emplace_back(phase, phase_.seconds());
    phase_.restart();
  }

 private:
  std::vector<std::pair<std::string, double>>& timings_;
  Stopwatch phase_;
};

/// "open (12 boundary edges), self-intersecting (40 triangle pairs)".
std::string describeDefects(const SurfaceDiagnosis& d) {
  std::vector<std::string> parts;
  const SurfaceTopology& t = d.topology;
  if (t.boundaryEdges)
    parts.push_back("open (" + std::to_string(t.boundaryEdges) + " boundary edges)");
  if (t.nonManifoldEdges)
    parts.push_back("non-manifold (" + std::to_string(t.nonManifoldEdges) +
                    " edges with more than two triangles)");
  if (d.selfIntersections)
    parts.push_back("self-intersecting (" + std::to_string(d.selfIntersections) +
                    " pairs of intersecting triangles)");
  std::string s;
  for (std::size_t i = 0; i < parts.size(); ++i) s += (i ? ", " : "") + parts[i];
  return s;
}

bool broken(const SurfaceDiagnosis& d) {
  return !d.closed() || !d.manifold() || d.selfIntersections > 0;
}

double cellSizeFor(const Box3& box, const MeshingOptions& o) {
  if (o.cellSize) {
    if (!(*o.cellSize > 0) || !std::isfinite(*o.cellSize))
      throw InputError("the cell size must be a positive number");
    return *o.cellSize;
  }
  if (o.cellsAlongLongest < 1) throw InputError("the number of cells must be at least 1");
  return box.diagonal().maxCoeff() / o.cellsAlongLongest;
}

/// "1.27e+30": a length for a message.
std::string shortNumber(double x) { return formatNumber(x, 3); }

/// Refuses a surface whose lengths would overflow or underflow downstream (kLargestLength and
/// kSmallestLength) and returns the cell size.
double checkedCellSize(const TriangleSurface& input, const MeshingOptions& options) {
  const Box3 box = bounds(input);
  for (const Vec3& p : input.vertices)
    if (!p.allFinite())
      throw InputError("a vertex has a non-finite coordinate (NaN or infinity); fix the surface");
  const double extent = box.diagonal().maxCoeff();
  const double largest = std::max(box.min().cwiseAbs().maxCoeff(), box.max().cwiseAbs().maxCoeff());
  const std::string spans = "its bounding box spans " + shortNumber(extent) +
                            " (largest |coordinate| " + shortNumber(largest) + ")";
  if (!(extent <= kLargestLength))
    throw InputError("the surface is too large for double precision: " + spans + ", more than " +
                     shortNumber(kLargestLength) +
                     " (2^100), so volumes and element moments (up to length^9) would overflow; "
                     "scale the model down (change its units) to span at most " +
                     shortNumber(kLargestLength));
  if (!(extent >= kSmallestLength))
    throw InputError("the surface is too small for double precision: " + spans + ", less than " +
                     shortNumber(kSmallestLength) +
                     " (2^-100), so volumes and element moments (up to length^9) would underflow "
                     "to zero; scale the model up (change its units) to span at least " +
                     shortNumber(kSmallestLength));
  const double h = cellSizeFor(box, options);
  if (!(h <= kLargestLength))
    throw InputError("the cell size " + shortNumber(h) + " is more than " +
                     shortNumber(kLargestLength) +
                     " (2^100), so cell volumes would overflow; use a smaller cell");
  if (!(h >= kSmallestLength))
    throw InputError("the cell size " + shortNumber(h) + " is less than " +
                     shortNumber(kSmallestLength) +
                     " (2^-100), so element volumes and moments (up to length^9) would "
                     "underflow; use fewer cells, or scale the model up");
  return h;
}

}  // namespace

namespace {

/// The input part of the report from the diagnosis of the surface as read.
void recordDiagnosis(const TriangleSurface& input, const SurfaceDiagnosis& d, MeshingReport& r) {
  r.inputVertices = input.vertices.size();
  r.inputTriangles = input.triangles.size();
  r.inputClosed = d.topology.closed();
  r.inputManifold = d.manifold();
  r.selfIntersections = d.selfIntersections;
  r.selfIntersectionsChecked = d.checkedSelfIntersections;
}

/// Orients a closed manifold surface, slices it with the grid of `cellSize` and merges slivers
/// into `result`, timing the phases "orient", "slice" and "merge_slivers".
void orientAndSlice(const TriangleSurface& closed, double cellSize, const MeshingOptions& options,
                    MeshingResult& result, PhaseTimer& timer,
                    const SurfaceTopology* topology = nullptr) {
  MeshingReport& r = result.report;
  bool reoriented = false;
  const TriangleSurface surface =
      orientToBoundVolume(closed, reoriented, &r.shells, &r.cavities, topology);
  if (reoriented) r.repairs.push_back("re-oriented the surface to bound its volume outward");
  r.inputVolume = enclosedVolume(surface);
  if (!(r.inputVolume > 0)) throw InputError("the surface encloses no volume");
  timer.done("orient");

  r.grid = Grid::covering(bounds(surface), cellSize);
  const int levels = options.octreeLevels;
  PolyMesh sliced = levels > 0 ? sliceSurfaceOctree(surface, r.grid, levels, &r.slice,
                                                    &result.elementLevels, options.progress)
                               : sliceSurface(surface, r.grid, &r.slice, nullptr, options.progress,
                                              &result.wholeCells);
  timer.done("slice");

  if (options.sliverTau > 0) {
    SliverMergeReport merge;
    const double finestCell = std::ldexp(r.grid.cellVolume(), -3 * levels);
    // A whole cell is no sliver while the threshold is well below its volume (its computed
    // volume and area are the cell's to round-off).
    if (options.sliverTau > 0.5) result.wholeCells.clear();
    result.mesh =
        mergeSlivers(std::move(sliced), options.sliverTau * finestCell, &merge, result.wholeCells);
    r.slivers = {merge.threshold, merge.slivers, merge.merged, merge.isolated};
    if (result.mesh.numElements() != merge.group.size())
      result.wholeCells =
          mergeWholeFlags(result.wholeCells, merge.group, result.mesh.numElements());
    if (levels > 0) {
      // A merged element is at the finest level of its parts.
      std::vector<int> merged(result.mesh.numElements(), 0);
      for (std::size_t e = 0; e < merge.group.size(); ++e)
        merged[merge.group[e]] = std::max(merged[merge.group[e]], result.elementLevels[e]);
      result.elementLevels = std::move(merged);
    }
  } else {
    result.mesh = std::move(sliced);
  }
  // What slicing freed is returned before the arrays of validation and writing are made, if
  // those (a number or a few per face) are too large to be made of it; smaller ones reuse it.
  releaseFreedMemoryBefore(result.mesh.numFaces(), sizeof(double));
  timer.done("merge_slivers");
}

/// The self-intersection test of a surface closed edge by edge (selfIntersectionsOfClosedSurface,
/// the costly, serial part of the diagnosis), run on another core from construction: it starts
/// before the topology says whether it applies, since it takes no input but the soup. Stopped
/// (not waited for to the end) if it does not apply.
class ClosedSurfaceTest {
 public:
  explicit ClosedSurfaceTest(const TriangleSurface& surface) {
    group_.run([this, &surface] {
      const Stopwatch start;
      count_ = selfIntersectionsOfClosedSurface(surface, &stop_);
      seconds_ = start.seconds();
    });
  }
  ~ClosedSurfaceTest() {
    stop_ = true;
    try {
      group_.wait();
    } catch (...) {  // an error of a test nobody reads
    }
  }
  ClosedSurfaceTest(const ClosedSurfaceTest&) = delete;
  ClosedSurfaceTest& operator=(const ClosedSurfaceTest&) = delete;

  /// The count, once the test is done.
  std::size_t count() {
    group_.wait();
    return count_.value();
  }
  double seconds() const { return seconds_; }
  /// Asks the test to stop early: its count will not be read.
  void stop() { stop_ = true; }

 private:
  tbb::task_group group_;
  std::atomic<bool> stop_{false};
  std::optional<std::size_t> count_;
  double seconds_ = 0.0;
};

/// meshSurface() for a surface closed edge by edge, manifold, without singular vertices or
/// degenerate triangles, the usual input: the surface is oriented and sliced while `test`
/// runs. The result, if the test finds no defect; otherwise nothing (the slicing is dropped,
/// and the caller repairs or refuses the surface from `d`).
std::optional<MeshingResult> meshWhileTesting(const TriangleSurface& input,
                                              const SurfaceTopology& topology, double cellSize,
                                              const MeshingOptions& options,
                                              ClosedSurfaceTest& test, SurfaceDiagnosis& d) {
  MeshingResult result;
  PhaseTimer timer(result.report.timings);
  std::exception_ptr failure;  // of the slicing; it matters only if the surface is sound
  try {
    orientAndSlice(input, cellSize, options, result, timer, &topology);
  } catch (...) {
    failure = std::current_exception();
  }
  d = diagnose(input, &topology, test.count());
  if (broken(d)) return std::nullopt;
  if (failure) std::rethrow_exception(failure);
  recordDiagnosis(input, d, result.report);
  // Measured beside the other phases: "total" then adds up more than the wall time.
  result.report.timings.insert(result.report.timings.begin(), {"check", test.seconds()});
  return result;
}

}  // namespace

MeshingResult meshSurface(const TriangleSurface& input, const MeshingOptions& options) {
  const Stopwatch start;
  auto finish = [&](MeshingResult& result) {
    result.report.seconds = start.seconds();
    if (options.checkGeometry) checkMeshing(result);
  };
  if (input.triangles.empty()) throw InputError("the surface has no triangles");
  const double cellSize = checkedCellSize(input, options);
  SurfaceDiagnosis d;
  bool diagnosed = false;
  ClosedSurfaceTest test(input);
  const SurfaceTopology topology = analyzeTopology(input);
  if (isClosedManifoldSoup(topology)) {
    if (std::optional<MeshingResult> done =
            meshWhileTesting(input, topology, cellSize, options, test, d)) {
      finish(*done);
      return std::move(*done);
    }
    diagnosed = true;
  } else {
    test.stop();
  }

  MeshingResult result;
  MeshingReport& r = result.report;
  PhaseTimer timer(r.timings);
  TriangleSurface surface = input;
  if (!diagnosed) d = diagnose(surface);
  recordDiagnosis(input, d, r);
  if (d.topology.degenerateTriangles > 0) {
    const std::size_t removed = removeDegenerateTriangles(surface);
    if (surface.triangles.empty())
      throw InputError("all " + std::to_string(removed) +
                       " triangles are degenerate (zero area); the surface encloses nothing");
    r.repairs.push_back("removed " + std::to_string(removed) + " degenerate triangles");
    d = diagnose(surface);
  }
  timer.done("check");

  if (broken(d)) {
    const std::string defects = describeDefects(d);
    switch (options.repair) {
      case RepairMode::None:
        throw InputError("the surface is " + defects +
                         "; use --repair fill to close holes in a manifold surface, or --repair "
                         "wrap to rebuild a closed surface around any triangle soup");
      case RepairMode::Fill: {
        if (!d.manifold())
          throw InputError("the surface is " + defects +
                           "; --repair fill needs a manifold surface, use --repair wrap");
        r.volumeBeforeRepair = enclosedVolume(surface);
        std::size_t holes = 0;
        surface = fillHoles(surface, holes);
        r.repairs.push_back("filled " + std::to_string(holes) + " holes");
        d = diagnose(surface);
        if (broken(d))
          throw InputError("the surface is still " + describeDefects(d) +
                           " after --repair fill; use --repair wrap");
        break;
      }
      case RepairMode::Wrap: {
        r.volumeBeforeRepair = d.closed() ? enclosedVolume(surface) : 0.0;
        // Alpha and offset follow the cell size: features finer than half a cell are closed
        // over, and the wrap stays within 1/30 of a cell of the input.
        const double alpha = 0.5 * cellSize, offset = cellSize / 30.0;
        surface = alphaWrap(surface, alpha, offset);
        std::ostringstream what;
        what << "alpha-wrapped (alpha " << alpha << ", offset " << offset << ") into "
             << surface.triangles.size() << " triangles";
        r.repairs.push_back(what.str());
        d = diagnose(surface);
        if (broken(d))
          throw InputError("alpha wrapping did not give a closed surface (" + describeDefects(d) +
                           "); try a smaller cell size");
        break;
      }
    }
    timer.done("repair");
  }

  orientAndSlice(surface, cellSize, options, result, timer);
  finish(result);
  return result;
}

void checkMeshing(MeshingResult& result) {
  checkMeshing(result.mesh, result.report, result.wholeCells);
}

void checkMeshing(const PolyMesh& mesh, MeshingReport& r, const std::vector<char>& wholeCells,
                  std::span<const double> volumes) {
  const Stopwatch start;
  r.geometry = checkGeometry(mesh, {}, volumes, wholeCells);
  r.elements = mesh.numElements();
  r.faces = r.geometry.faces;
  r.interiorFaces = r.geometry.interiorFaces;
  r.boundaryFaces = r.geometry.boundaryFaces;
  r.outputVolume = r.geometry.volume;
  r.volumeRelError = std::abs(r.outputVolume - r.inputVolume) / r.inputVolume;
  // Shape counts in parallel: (hexahedra, non-convex).
  using Counts = std::pair<std::size_t, std::size_t>;
  const Counts counts = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.numElements(), 1024), Counts{0, 0},
      [&](const tbb::blocked_range<std::size_t>& range, Counts c) {
        for (std::size_t e = range.begin(); e != range.end(); ++e) {
          const bool hex =
              (!wholeCells.empty() && wholeCells[e]) || isGridHexahedron(mesh, ElementId(e));
          c.first += hex;
          if (!hex && !isConvex(mesh, ElementId(e))) ++c.second;
        }
        return c;
      },
      [](Counts a, const Counts& b) {
        return Counts{a.first + b.first, a.second + b.second};
      });
  r.hexahedra = counts.first;
  r.nonconvex = counts.second;
  r.polyhedra = r.elements - r.hexahedra;
  const double seconds = start.seconds();
  r.timings.emplace_back("validate", seconds);
  r.seconds += seconds;
}

}  // namespace polydg
