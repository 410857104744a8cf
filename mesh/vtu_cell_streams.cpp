#include "mesh/vtu_cell_streams.h"

#include <algorithm>
#include <bit>
#include <functional>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <boost/container/small_vector.hpp>

#include "mesh/face_triangulation.h"
#include "mesh/per_element.h"
#include "mesh/vtk_cell_types.h"

namespace polydg {

namespace {

using vtk_format::GeneratedInts;

/// The distinct vertices of one element at a time, numbered in order of first use: a linear
/// search while there are few (a grid cell has 8), a hash table once there are more (a cut cell
/// has tens, and searching them all for every use made numbering quadratic).
class CornerNumbers {
 public:
  void clear() {
    vertices_.clear();
    table_.clear();
  }
  /// The number of v, the next one if v is new.
  std::uint32_t number(VertexId v) {
    if (table_.empty()) {
      for (std::size_t i = 0; i < vertices_.size(); ++i)
        if (vertices_[i] == v) return static_cast<std::uint32_t>(i);
      return add(v);
    }
    std::size_t slot = hash(v);
    for (; table_[slot] != kEmpty; slot = (slot + 1) & (table_.size() - 1))
      if (vertices_[table_[slot]] == v) return table_[slot];
    table_[slot] = static_cast<std::uint32_t>(vertices_.size());
    return add(v);
  }
  std::span<const VertexId> vertices() const { return {vertices_.data(), vertices_.size()}; }

 private:
  static constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
  static constexpr std::size_t kLinear = 16;  ///< vertices searched linearly at most

  std::uint32_t add(VertexId v) {
    vertices_.push_back(v);
    // Rebuilt at a quarter full, so that probes stay short.
    if (vertices_.size() > kLinear && 4 * vertices_.size() > table_.size()) {
      table_.assign(std::bit_ceil(8 * vertices_.size()), kEmpty);
      shift_ = 64 - std::countr_zero(table_.size());
      for (std::size_t i = 0; i < vertices_.size(); ++i) {
        std::size_t slot = hash(vertices_[i]);
        while (table_[slot] != kEmpty) slot = (slot + 1) & (table_.size() - 1);
        table_[slot] = static_cast<std::uint32_t>(i);
      }
    }
    return static_cast<std::uint32_t>(vertices_.size() - 1);
  }
  /// Fibonacci hashing: the top bits of v times 2^64 / golden ratio.
  std::size_t hash(VertexId v) const {
    return static_cast<std::size_t>((v.value * 0x9e3779b97f4a7c15ull) >> shift_);
  }

  boost::container::small_vector<VertexId, 32> vertices_;
  std::vector<std::uint32_t> table_;  ///< indices into vertices_, or kEmpty
  int shift_ = 0;                     ///< 64 - log2(table_.size())
};

/// Calls f(use, record) for each record of element e, in file order.
template <class F>
void forEachRecordOf(const PolyMesh& mesh, const FaceRecords& records, ElementId e, F&& f) {
  for (const FaceUse& use : mesh.element(e).faces)
    for (std::size_t k = 0; k < records.count(use.face); ++k) f(use, records.record(use.face, k));
}

/// Numbers the vertices of element e's records in file order (so `numbers` ends with its
/// corners in order of first use) and calls f(use, record, corner) for each record, corner[i]
/// being the number of record[i].
template <class F>
void forEachRecord(const PolyMesh& mesh, const FaceRecords& records, ElementId e,
                   CornerNumbers& numbers, F&& f) {
  numbers.clear();
  boost::container::small_vector<std::uint32_t, 16> corner;
  forEachRecordOf(mesh, records, e, [&](const FaceUse& use, std::span<const VertexId> record) {
    corner.resize(record.size());
    for (std::size_t i = 0; i < record.size(); ++i) corner[i] = numbers.number(record[i]);
    f(use, record, std::span<const std::uint32_t>(corner.data(), corner.size()));
  });
}

/// A whole grid cell, as CellStreams' `boxes` give it: six sides of four corners, eight corners.
constexpr std::uint32_t kBoxSides = 6, kSideCorners = 4, kBoxCorners = 8;

/// A count of one cell, which RunningEnds keeps in 32 bits.
std::uint32_t cellCount(std::size_t n) {
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw std::length_error("writeVtu: a cell has " + std::to_string(n) +
                            " values in one array; the writer counts at most 2^32 - 1 per cell");
  return static_cast<std::uint32_t>(n);
}

/// Positions [begin, end) of a stream produced value by value from position `at` on: put()
/// writes the values in that window to out[position - begin] and drops the others, so a range
/// may start and end inside a cell.
class Window {
 public:
  Window(std::uint64_t at, std::size_t begin, std::size_t end, std::int64_t* out)
      : at_(at), begin_(begin), end_(end), out_(out) {}
  void put(std::int64_t value) {
    if (at_ >= begin_ && at_ < end_) out_[at_ - begin_] = value;
    ++at_;
  }

 private:
  std::uint64_t at_;
  std::size_t begin_, end_;
  std::int64_t* out_;
};

/// The values of a cell whose whole run lies in the range being written: put() stores each
/// in turn, with none of Window's bounds to check.
class WholeRun {
 public:
  explicit WholeRun(std::int64_t* out) : out_(out) {}
  void put(std::int64_t value) { *out_++ = value; }

 private:
  std::int64_t* out_;
};

/// Writes values [begin, end) of a stream whose cells' runs end at `ends`: emit(c, window)
/// puts all of cell c's values, for each cell from the one holding `begin` on. The cells inside
/// the range (all but at most the first and the last) get a WholeRun, the others a Window.
template <class Emit>
void fillByCell(const RunningEnds& ends, std::size_t begin, std::size_t end, std::int64_t* out,
                Emit&& emit) {
  for (std::size_t c = ends.cellAt(begin); c < ends.size(); ++c) {
    const std::uint64_t first = ends.begin(c), last = ends.end(c);
    if (first >= end) break;
    if (first >= begin && last <= end) {
      WholeRun run(out + (first - begin));
      emit(c, run);
    } else {
      Window window(first, begin, end, out);
      emit(c, window);
    }
  }
}

/// `size` values, value i being valueOf(i).
template <class ValueOf>
GeneratedInts eachOf(std::size_t size, std::int64_t largest, ValueOf valueOf) {
  return {size, largest, [valueOf](std::size_t begin, std::size_t end, std::int64_t* out) {
            for (std::size_t i = begin; i < end; ++i)
              out[i - begin] = static_cast<std::int64_t>(valueOf(i));
          }};
}

}  // namespace

FaceRecords::FaceRecords(const PolyMesh& mesh) : mesh_(mesh), isHoled_(mesh.numFaces(), false) {
  for (std::size_t f = 0; f < mesh.numFaces(); ++f)
    if (mesh.face(FaceId(f)).numLoops() != 1) {
      isHoled_[f] = true;
      holed_.push_back(FaceId(f));
    }
  std::vector<std::vector<std::array<VertexId, 3>>> triangles(holed_.size());
  tbb::parallel_for(std::size_t(0), holed_.size(), [&](std::size_t i) {
    if (mesh.face(holed_[i]).numLoops() > 1) triangles[i] = triangulateFace(mesh, holed_[i]);
  });
  holedBegin_.assign(holed_.size() + 1, 0);
  for (std::size_t i = 0; i < holed_.size(); ++i)
    holedBegin_[i + 1] = holedBegin_[i] + triangles[i].size();
  triangles_.reserve(holedBegin_.back());
  for (const auto& t : triangles) triangles_.insert(triangles_.end(), t.begin(), t.end());
}

std::size_t FaceRecords::holed(FaceId f) const {
  return static_cast<std::size_t>(std::lower_bound(holed_.begin(), holed_.end(), f) -
                                  holed_.begin());
}

RunningEnds::RunningEnds(std::vector<std::uint32_t> counts) {
  const std::uint64_t total = std::accumulate(counts.begin(), counts.end(), std::uint64_t{0});
  if (total <= std::numeric_limits<std::uint32_t>::max()) {
    std::inclusive_scan(counts.begin(), counts.end(), counts.begin());
    narrow_ = std::move(counts);
  } else {
    wide_.resize(counts.size());
    std::inclusive_scan(counts.begin(), counts.end(), wide_.begin(), std::plus<>(),
                        std::uint64_t{0});
  }
}

std::size_t RunningEnds::cellAt(std::uint64_t at) const {
  if (wide_.empty())
    return static_cast<std::size_t>(std::upper_bound(narrow_.begin(), narrow_.end(), at) -
                                    narrow_.begin());
  return static_cast<std::size_t>(std::upper_bound(wide_.begin(), wide_.end(), at) - wide_.begin());
}

CellStreams::CellStreams(const PolyMesh& mesh, std::span<const char> boxes)
    : mesh_(mesh), records_(mesh) {
  requireNoneOrOnePerElement(boxes.size(), mesh, "CellStreams", "box flags");
  findCorners(boxes);
  points_ = groupPoints(mesh, corners_);
  order_.resize(mesh.numElements());
  for (std::size_t e = 0; e < order_.size(); ++e) order_[e] = ElementId(e);
  // Cells in increasing order of their point count (stable), see kElementArray.
  std::stable_sort(order_.begin(), order_.end(),
                   [&](ElementId a, ElementId b) { return corners_.count(a) < corners_.count(b); });
  std::vector<std::uint32_t> cornerCount(order_.size());
  for (std::size_t c = 0; c < order_.size(); ++c) cornerCount[c] = corners_.count(order_[c]);
  connectivityEnd_ = RunningEnds(std::move(cornerCount));
  // Each cell's records and `faces` values, counted in cell order only now: not held while the
  // points are grouped, when the writer holds the most.
  std::vector<std::uint32_t> recordCount(order_.size()), streamCount(order_.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order_.size(), 512),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t c = r.begin(); c != r.end(); ++c) {
                        if (corners_.isBox(order_[c])) {
                          recordCount[c] = kBoxSides;
                          streamCount[c] = 1 + kBoxSides * (1 + kSideCorners);
                          continue;
                        }
                        std::size_t records = 0, stream = 1;
                        forEachRecordOf(mesh_, records_, order_[c],
                                        [&](const FaceUse&, std::span<const VertexId> record) {
                                          ++records;
                                          stream += 1 + record.size();
                                        });
                        recordCount[c] = cellCount(records);
                        streamCount[c] = cellCount(stream);
                      }
                    });
  recordEnd_ = RunningEnds(std::move(recordCount));
  faceEnd_ = RunningEnds(std::move(streamCount));
  largest_.point = largest_.cornerVertex;
  for (const std::uint32_t p : points_.cornerPoint)
    largest_.point = std::max<std::int64_t>(largest_.point, p);
  for (const Face& face : mesh.faces())
    largest_.origin = std::max(largest_.origin, static_cast<std::int64_t>(face.origin));
  for (VertexId v : points_.pointVertex)
    largest_.vertex = std::max<std::int64_t>(largest_.vertex, v.value);
}

void CellStreams::findCorners(std::span<const char> boxes) {
  const std::size_t ne = mesh_.numElements();
  std::vector<std::uint32_t> cornerCount(ne + 1, 0);  // element e's at e + 1
  // Per element, whether its corners are read from its first two sides (ElementCorners' boxes).
  std::vector<char> implicit(ne, 0);
  auto most = [](Largest a, const Largest& b) {
    a.recordsPerCell = std::max(a.recordsPerCell, b.recordsPerCell);
    a.recordSize = std::max(a.recordSize, b.recordSize);
    a.face = std::max(a.face, b.face);
    a.reversed = std::max(a.reversed, b.reversed);
    a.cornerVertex = std::max(a.cornerVertex, b.cornerVertex);
    return a;
  };
  const Largest counted = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, ne, 512), Largest{},
      [&](const tbb::blocked_range<std::size_t>& r, Largest largest) {
        CornerNumbers numbers;
        for (std::size_t e = r.begin(); e != r.end(); ++e) {
          std::size_t records = 0, sideCorners = 0;  // of a grid box
          if (!boxes.empty() && boxes[e] && ElementCorners::hasBoxSides(mesh_, ElementId(e))) {
            // Six single loops of four corners, the first two disjoint, the others on their
            // eight: the first two sides' corners, in order, are those of first use.
            for (const FaceUse& use : mesh_.element(ElementId(e)).faces) {
              largest.face = std::max<std::int64_t>(largest.face, use.face.value);
              largest.reversed = std::max<std::int64_t>(largest.reversed, use.reversed);
            }
            largest.recordSize = std::max<std::int64_t>(largest.recordSize, kSideCorners);
            largest.recordsPerCell = std::max<std::int64_t>(largest.recordsPerCell, kBoxSides);
            for (std::size_t s = 0; s < 2; ++s)
              for (const VertexId v :
                   mesh_.face(mesh_.element(ElementId(e)).faces[s].face).vertices)
                largest.cornerVertex = std::max<std::int64_t>(largest.cornerVertex, v.value);
            implicit[e] = 1;
            cornerCount[e + 1] = kBoxCorners;
            continue;
          }
          forEachRecord(mesh_, records_, ElementId(e), numbers,
                        [&](const FaceUse& use, std::span<const VertexId> record, auto) {
                          ++records;
                          sideCorners += record.size() == kSideCorners;
                          largest.recordSize = std::max(largest.recordSize,
                                                        static_cast<std::int64_t>(record.size()));
                          largest.face = std::max<std::int64_t>(largest.face, use.face.value);
                          largest.reversed = std::max<std::int64_t>(largest.reversed, use.reversed);
                        });
          const std::size_t found = numbers.vertices().size();
          for (const VertexId v : numbers.vertices())
            largest.cornerVertex = std::max<std::int64_t>(largest.cornerVertex, v.value);
          if (!boxes.empty() && boxes[e] &&
              (found != kBoxCorners || records != kBoxSides || sideCorners != kBoxSides))
            throw std::logic_error("writeVtu: element " + std::to_string(e) +
                                   " was given as a grid box but has " + std::to_string(records) +
                                   " faces and " + std::to_string(found) + " corners");
          largest.recordsPerCell =
              std::max(largest.recordsPerCell, static_cast<std::int64_t>(records));
          cornerCount[e + 1] = cellCount(found);
        }
        return largest;
      },
      most);
  largest_ = most(largest_, counted);
  corners_ = ElementCorners(mesh_, std::move(cornerCount), implicit);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, ne, 512), [&](const tbb::blocked_range<std::size_t>& r) {
        CornerNumbers numbers;
        for (std::size_t e = r.begin(); e != r.end(); ++e) {
          if (implicit[e]) continue;
          forEachRecord(mesh_, records_, ElementId(e), numbers, [](auto&&...) {});
          const auto found = numbers.vertices();
          std::copy(found.begin(), found.end(), corners_.stored(ElementId(e)).begin());
        }
      });
}

GeneratedInts CellStreams::connectivity() const {
  return {connectivityEnd_.total(), largest_.point,
          [this](std::size_t begin, std::size_t end, std::int64_t* out) {
            fillByCell(connectivityEnd_, begin, end, out, [&](std::size_t c, auto& window) {
              std::uint32_t i = corners_.first(order_[c]);
              corners_.forEach(order_[c], [&](VertexId v) { window.put(points_.point(i++, v)); });
            });
          }};
}

GeneratedInts CellStreams::offsets() const {
  return eachOf(numCells(), static_cast<std::int64_t>(connectivityEnd_.total()),
                [this](std::size_t c) { return connectivityEnd_.end(c); });
}

GeneratedInts CellStreams::types() const {
  return eachOf(numCells(), numCells() > 0 ? vtk_format::kVtkPolyhedron : 0,
                [](std::size_t) { return vtk_format::kVtkPolyhedron; });
}

GeneratedInts CellStreams::faces() const {
  return {faceEnd_.total(),
          std::max({largest_.point, largest_.recordsPerCell, largest_.recordSize}),
          [this](std::size_t begin, std::size_t end, std::int64_t* out) {
            CornerNumbers numbers;
            const bool vertexIds = points_.pointsAreVertices();
            fillByCell(faceEnd_, begin, end, out, [&](std::size_t c, auto& window) {
              const ElementId e = order_[c];
              const std::size_t first = corners_.first(e);
              window.put(static_cast<std::int64_t>(recordEnd_.end(c) - recordEnd_.begin(c)));
              // A record's size, then the points of its vertices 0 .. n-1 (pointOf(i)); backwards
              // for a reversed use, keeping the first vertex first: v0, v(n-1), ..., v1.
              auto putRecord = [&](const FaceUse& use, std::size_t n, auto&& pointOf) {
                window.put(static_cast<std::int64_t>(n));
                for (std::size_t i = 0; i < n; ++i)
                  window.put(pointOf(use.reversed ? (n - i) % n : i));
              };
              if (vertexIds) {  // a corner's point is its vertex: the records' ids as they are
                forEachRecordOf(
                    mesh_, records_, e, [&](const FaceUse& use, std::span<const VertexId> record) {
                      putRecord(use, record.size(),
                                [&](std::size_t i) { return std::int64_t(record[i].value); });
                    });
                return;
              }
              // The records' vertices are numbered as elementCorners numbered them.
              forEachRecord(mesh_, records_, e, numbers,
                            [&](const FaceUse& use, std::span<const VertexId> record,
                                std::span<const std::uint32_t> corner) {
                              putRecord(use, corner.size(), [&](std::size_t i) {
                                return std::int64_t(points_.point(first + corner[i], record[i]));
                              });
                            });
            });
          }};
}

GeneratedInts CellStreams::faceOffsets() const {
  return eachOf(numCells(), static_cast<std::int64_t>(faceEnd_.total()),
                [this](std::size_t c) { return faceEnd_.end(c); });
}

template <class Value>
GeneratedInts CellStreams::perRecord(std::int64_t largest, Value value) const {
  return {recordEnd_.total(), largest,
          [this, value](std::size_t begin, std::size_t end, std::int64_t* out) {
            fillByCell(recordEnd_, begin, end, out, [&](std::size_t c, auto& window) {
              for (const FaceUse& use : mesh_.element(order_[c]).faces)
                for (std::size_t k = 0; k < records_.count(use.face); ++k) window.put(value(use));
            });
          }};
}

GeneratedInts CellStreams::faceGroup() const {
  return perRecord(largest_.face, [](const FaceUse& use) { return use.face.value; });
}

GeneratedInts CellStreams::faceReversed() const {
  return perRecord(largest_.reversed, [](const FaceUse& use) { return use.reversed ? 1 : 0; });
}

GeneratedInts CellStreams::faceOrigin() const {
  return eachOf(mesh_.numFaces(), largest_.origin, [this](std::size_t f) {
    return static_cast<std::int64_t>(mesh_.face(FaceId(f)).origin);
  });
}

GeneratedInts CellStreams::element() const {
  return eachOf(numCells(), static_cast<std::int64_t>(numCells() > 0 ? numCells() - 1 : 0),
                [this](std::size_t c) { return order_[c].value; });
}

GeneratedInts CellStreams::pointVertex() const {
  return eachOf(points_.numPoints(), largest_.vertex,
                [this](std::size_t p) { return points_.pointVertex[p].value; });
}

}  // namespace polydg
