// The polyhedral mesh: shared vertices, planar polygonal faces with holes, and elements that are
// closed sets of oriented faces; elements and faces may be non-convex.
#pragma once

#include <compare>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <iterator>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include "polydg/mesh/ids.h"
#include "polydg/mesh/loop_ends.h"
#include "polydg/util/small_vector.h"

namespace polydg {

using Vec3 = Eigen::Vector3d;

/// Where a face came from. Interior faces are shared by two elements; every other tag marks a
/// boundary face (or, before a mesh is finished, a face that will be one).
enum class FaceOrigin : std::uint8_t {
  Interior = 0,  ///< shared by two elements
  Surface = 1,   ///< lies on the input surface
  Cut = 2,       ///< created by a plane cut; the two sides are not coupled
  Box = 3,       ///< on the outer boundary of a generated box or grid
  Imported = 4,  ///< boundary face read from a file that did not say where it came from
};
std::string_view toString(FaceOrigin origin);

/// How an element uses a face. `reversed == false`: the face's own normal (right-hand rule on
/// its outer loop) points out of the element; `reversed == true`: it points into the element.
struct FaceUse {
  FaceId face;
  bool reversed = false;
};

/// A face: one outer loop followed by zero or more hole loops, all in one plane. The outer loop
/// runs counter-clockwise about the face normal, holes clockwise, so the face normal is the
/// Newell normal of all loops together. `front` is the element the normal points out of,
/// `back` the element it points into (invalid for a boundary face).
struct Face {
  /// All loops, concatenated; up to 4 corners are stored inline (no allocation): nearly every
  /// face of a sliced mesh is a grid cell's side (95% of the bunny's at 200 cells have 3 or 4).
  /// At most 65,535 corners: the 16-bit counts leave the last 4 bytes of its room to `loopEnd`,
  /// so that a face is 40 bytes, not 48 (5.4 million of them for the bunny at 200 cells).
  [[no_unique_address]] SmallVector<VertexId, 4, std::uint16_t> vertices;
  /// Loop k ends at loopEnd[k]; a single loop's end is kept inline, holes' on the heap.
  LoopEnds loopEnd;
  ElementId front;
  ElementId back;
  FaceOrigin origin = FaceOrigin::Interior;

  std::size_t numLoops() const { return loopEnd.size(); }
  std::span<const VertexId> loop(std::size_t k) const {
    const std::size_t begin = k == 0 ? 0 : loopEnd[k - 1];
    return {vertices.data() + begin, loopEnd[k] - begin};
  }
  bool isBoundary() const { return !back.valid(); }
};

/// The faces of an element, each with its orientation. A use is packed in 32 bits (the face id
/// in the low 31, `reversed` in the top one), so that a grid cell's six fit inline and an
/// element is 32 bytes, not 56 (1.65 million of them for the bunny at 200 cells). Reading
/// yields FaceUse values (copies); a use is changed with set(). Face ids go up to 2^31 - 2.
class FaceList {
 public:
  using value_type = FaceUse;
  using size_type = std::size_t;

  /// Yields FaceUse values: an input iterator for the standard algorithms, random access in
  /// C++20's terms.
  class const_iterator {
   public:
    using iterator_category = std::input_iterator_tag;
    using iterator_concept = std::random_access_iterator_tag;
    using value_type = FaceUse;
    using difference_type = std::ptrdiff_t;
    using reference = FaceUse;
    using pointer = void;

    const_iterator() = default;
    explicit const_iterator(const std::uint32_t* at) : at_(at) {}
    FaceUse operator*() const { return unpack(*at_); }
    FaceUse operator[](difference_type i) const { return unpack(at_[i]); }
    const_iterator& operator++() {
      ++at_;
      return *this;
    }
    const_iterator operator++(int) {
      const_iterator old = *this;
      ++at_;
      return old;
    }
    const_iterator& operator--() {
      --at_;
      return *this;
    }
    const_iterator operator--(int) {
      const_iterator old = *this;
      --at_;
      return old;
    }
    const_iterator& operator+=(difference_type n) {
      at_ += n;
      return *this;
    }
    const_iterator& operator-=(difference_type n) {
      at_ -= n;
      return *this;
    }
    friend const_iterator operator+(const_iterator it, difference_type n) { return it += n; }
    friend const_iterator operator+(difference_type n, const_iterator it) { return it += n; }
    friend const_iterator operator-(const_iterator it, difference_type n) { return it -= n; }
    friend difference_type operator-(const_iterator a, const_iterator b) { return a.at_ - b.at_; }
    friend auto operator<=>(const_iterator, const_iterator) = default;

   private:
    const std::uint32_t* at_ = nullptr;
  };
  using iterator = const_iterator;

  FaceList() = default;
  FaceList(std::initializer_list<FaceUse> uses) { assign(uses.begin(), uses.end()); }

  size_type size() const { return packed_.size(); }
  bool empty() const { return packed_.empty(); }
  const_iterator begin() const { return const_iterator(packed_.data()); }
  const_iterator end() const { return const_iterator(packed_.data() + packed_.size()); }
  FaceUse operator[](size_type i) const { return unpack(packed_[i]); }
  FaceUse front() const { return unpack(packed_.front()); }
  FaceUse back() const { return unpack(packed_.back()); }

  /// Throws std::length_error for a face id beyond 2^31 - 2.
  void push_back(const FaceUse& use) { packed_.push_back(pack(use)); }
  void set(size_type i, const FaceUse& use) { packed_[i] = pack(use); }
  void reserve(size_type n) { packed_.reserve(n); }
  void clear() { packed_.clear(); }
  void erase(size_type i) { packed_.erase(packed_.begin() + static_cast<std::ptrdiff_t>(i)); }
  template <class It, class = typename std::iterator_traits<It>::iterator_category>
  void assign(It first, It last) {
    packed_.clear();
    for (; first != last; ++first) push_back(*first);
  }

  friend bool operator==(const FaceList& a, const FaceList& b) { return a.packed_ == b.packed_; }

 private:
  static constexpr std::uint32_t kReversed = 0x80000000u;
  static constexpr std::uint32_t kNoFace = 0x7fffffffu;  ///< an invalid FaceId

  static std::uint32_t pack(const FaceUse& use) {
    const std::uint32_t face = use.face.valid() ? use.face.value : kNoFace;
    if (use.face.valid() && face >= kNoFace)
      throw std::length_error("FaceList: a face id beyond 2^31 - 2 (" +
                              std::to_string(use.face.value) + ")");
    return face | (use.reversed ? kReversed : 0u);
  }
  static FaceUse unpack(std::uint32_t packed) {
    const std::uint32_t face = packed & ~kReversed;
    return {face == kNoFace ? FaceId() : FaceId(face), (packed & kReversed) != 0};
  }

  SmallVector<std::uint32_t, 6> packed_;
};

struct Element {
  FaceList faces;
};
static_assert(sizeof(Element) == 32, "an element is its packed face uses");
static_assert(sizeof(Face) == 40, "a face's loop ends sit in its corners' padding");

/// The group of an element left out by PolyMesh::mergeElementGroups.
inline constexpr std::uint32_t kDroppedElement = 0xffffffffu;

/// A loop of vertex ids; used to describe faces to the mesh.
using Loop = std::vector<VertexId>;

/// A polyhedral mesh. Topology (faces, elements) and vertex positions live together here; data
/// computed from them (moments, solutions) lives outside in FaceData / ElementData containers.
///
/// Faces are shared: two elements that touch across a polygon hold the same FaceId, one with
/// `reversed == false` (front) and one with `reversed == true` (back).
class PolyMesh {
 public:
  // --- vertices ----------------------------------------------------------------------------
  std::size_t numVertices() const { return positions_.size(); }
  const Vec3& position(VertexId v) const { return positions_[v]; }
  const VertexData<Vec3>& positions() const { return positions_; }
  /// Mutable positions, for transforming a mesh in place (topology is unaffected).
  VertexData<Vec3>& positions() { return positions_; }
  VertexId addVertex(const Vec3& p);
  /// Reserves room, to build large meshes without reallocation.
  void reserve(std::size_t vertices, std::size_t faces, std::size_t elements) {
    positions_.raw().reserve(vertices);
    faces_.raw().reserve(faces);
    elements_.raw().reserve(elements);
  }
  /// Replaces the whole mesh with prebuilt arrays, for builders that assemble a large mesh in
  /// parallel. The caller guarantees consistency: face ids in elements in range, each face's
  /// front/back the elements that use it unreversed/reversed (checkGeometry() checks a finished
  /// mesh).
  void assign(VertexData<Vec3> positions, FaceData<Face> faces, ElementData<Element> elements) {
    positions_ = std::move(positions);
    faces_ = std::move(faces);
    elements_ = std::move(elements);
    openFaces_.clear();
    openFacesStale_ = true;
  }

  // --- faces -------------------------------------------------------------------------------
  std::size_t numFaces() const { return faces_.size(); }
  const Face& face(FaceId f) const { return faces_[f]; }
  const FaceData<Face>& faces() const { return faces_; }
  /// Sets the origin tag of a boundary face (interior faces stay `Interior`).
  void setOrigin(FaceId f, FaceOrigin origin);

  // --- elements ----------------------------------------------------------------------------
  std::size_t numElements() const { return elements_.size(); }
  const Element& element(ElementId e) const { return elements_[e]; }
  const ElementData<Element>& elements() const { return elements_; }

  /// Adds an element bounded by `boundary`: each entry is one face given as loops (outer
  /// first, then holes) ordered so that the normal points OUT of the new element. A face whose
  /// loops equal, reversed, those of an existing face with a free back side is shared with that
  /// face's element (it becomes an interior face); otherwise a new face is created with tag
  /// `boundaryOrigin` — also when the polygon would be used a third time or twice with the same
  /// orientation, so that such (invalid) input is kept and reported by checkGeometry() as duplicate
  /// faces rather than rejected here. Returns the new element's id.
  ElementId addElement(const std::vector<std::vector<Loop>>& boundary,
                       FaceOrigin boundaryOrigin = FaceOrigin::Imported);

  /// As above with one origin per face. Only faces tagged `Interior` (grid or cut caps known to
  /// be shared) are matched with existing faces; every other face is created new, so two
  /// touching surface faces of separate objects are never glued together.
  ElementId addElement(const std::vector<std::vector<Loop>>& boundary,
                       const std::vector<FaceOrigin>& origins);

  /// Adds an element from existing faces and orientations. Each face must have a free side
  /// (front if `reversed == false`, back otherwise). Used by readers that build faces first.
  ElementId addElementFromFaces(std::span<const FaceUse> faces);
  ElementId addElementFromFaces(const std::vector<FaceUse>& faces) {
    return addElementFromFaces(std::span<const FaceUse>(faces.data(), faces.size()));
  }
  ElementId addElementFromFaces(const FaceList& faces) {
    const std::vector<FaceUse> uses(faces.begin(), faces.end());
    return addElementFromFaces(std::span<const FaceUse>(uses.data(), uses.size()));
  }

  /// Adds a face from loops without attaching it to an element.
  FaceId addFace(std::vector<Loop> loops, FaceOrigin origin);
  /// The same from all loops' vertices concatenated and each loop's end offset.
  FaceId addFace(std::span<const VertexId> vertices, std::span<const std::uint32_t> loopEnd,
                 FaceOrigin origin);

  /// A face for a new element, given outward like addElement's: if an existing face with a free
  /// back side is this polygon reversed, that face, used reversed; otherwise a new face tagged
  /// `origin`, used as given (and offered to later calls).
  FaceUse findOrCreateFace(std::span<const VertexId> vertices,
                           std::span<const std::uint32_t> loopEnd, FaceOrigin origin);

  /// Merges elements in place: `group[e]` (0 .. groups-1) is element e's new element, or
  /// kDroppedElement to leave e out with its faces (it may share faces only with elements also
  /// left out). Faces between two members of one group disappear, the others keep their
  /// vertices, orientation and origin; element and face ids are renumbered (new element g is
  /// group g; faces keep their relative order). Vertices are unchanged. Groups numbered in order
  /// of their first element need no second element list.
  void mergeElementGroups(const std::vector<std::uint32_t>& group, std::size_t groups);

  // --- in-place editing (cut/): each operation costs O(faces touched), never O(mesh) -------

  /// Removes element e's use of face f and clears that side of f (f keeps its vertices and
  /// origin; a face left with only a back element must be reversed or removed by the caller).
  /// Throws std::invalid_argument if e does not use f.
  void detachFace(ElementId e, FaceId f);
  /// Appends `use` to element e's faces and sets that side of the face to e; a face then used
  /// from both sides becomes `Interior`. Throws std::invalid_argument if the side is taken.
  void attachFace(ElementId e, FaceUse use);
  /// Reverses a face in place: every loop traversed the other way with its first vertex kept
  /// first (so the face's reference point and area-positive moments are unchanged, its normal
  /// flips), front and back swapped, and the `reversed` flag of each element's use flipped.
  void reverseFace(FaceId f);
  /// Removes an unused face (no front, no back) by moving the last face into its slot and
  /// patching the uses of the moved face's elements. Returns the id the moved face had
  /// (invalid if f was the last face): that face is now f.
  FaceId removeFace(FaceId f);
  /// Removes an element without faces (see detachFace) by moving the last element into its
  /// slot and patching the front/back links of the moved element's faces. Returns the id the
  /// moved element had (invalid if e was the last element): that element is now e.
  ElementId removeElement(ElementId e);
  /// Inserts vertex p between a and b wherever a and b follow each other (either way) in a
  /// loop of face f: p must lie on that edge. Returns true if the face changed.
  bool splitEdge(FaceId f, VertexId a, VertexId b, VertexId p);

 private:
  VertexData<Vec3> positions_;
  FaceData<Face> faces_;
  ElementData<Element> elements_;
  /// Boundary faces by the sorted list of their vertex ids, for sharing in addElement; rebuilt
  /// on demand after ids change.
  std::unordered_multimap<std::uint64_t, FaceId> openFaces_;
  bool openFacesStale_ = false;
};

/// Order-independent key of a vertex set (FNV-1a over the sorted ids): equal sets, equal keys.
std::uint64_t vertexSetKey(std::span<const VertexId> vertices);

/// True if face `a`'s loops, reversed, equal `loops` (same loops, each the same cycle
/// traversed the other way, in any rotation; hole order is irrelevant).
bool isReverseOf(const Face& a, const std::vector<Loop>& loops);
/// The same with loops given as concatenated vertices and loop ends.
bool isReverseOf(const Face& a, std::span<const VertexId> vertices,
                 std::span<const std::uint32_t> loopEnd);

}  // namespace polydg
