#include "polydg/integrate/moment_cache.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

#include "util/resident.h"

namespace polydg {

namespace {
/// Below this many items a loop runs serially: spawning tasks would cost more than it saves.
constexpr std::size_t kParallelGrain = 256;

template <class F>
void forEach(std::size_t n, F&& f) {
  if (n < 2 * kParallelGrain) {
    for (std::size_t i = 0; i < n; ++i) f(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kParallelGrain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
                    });
}
}  // namespace

MomentCache::MomentCache(const PolyMesh& mesh, int degree)
    : mesh_(&mesh), degree_(degree), stride_(numMonomials(degree)) {
  if (degree < 0 || degree > kMaxMomentDegree)
    throw std::invalid_argument("MomentCache: degree outside 0.." +
                                std::to_string(kMaxMomentDegree));
  sync();
}

void MomentCache::sync() {
  const std::size_t nf = mesh_->numFaces(), ne = mesh_->numElements();
  const std::size_t oldFaces = std::min(faceNormals_.size(), nf);
  const std::size_t oldElements = std::min(elementOrigins_.size(), ne);
  // A cache of millions of faces is hundreds of MB, which one thread would fault in alone.
  growResident(faceMoments_, nf * stride_, 0.0);
  growResident(elementMoments_, ne * stride_, 0.0);
  growResident(faceNormals_.raw(), nf, Vec3(Vec3::Zero()));
  growResident(elementOrigins_.raw(), ne, Vec3(Vec3::Zero()));
  if (oldFaces == 0 && oldElements == 0 && dirtyFaces_.empty() && dirtyElements_.empty()) {
    // A new cache: everything is dirty, listed in id order, without visiting each face's
    // elements (update() does not depend on the order of the lists).
    faceDirty_.assign(nf, 1);
    elementDirty_.assign(ne, 1);
    dirtyFaces_.resize(nf);
    dirtyElements_.resize(ne);
    forEach(nf, [&](std::size_t f) { dirtyFaces_[f] = FaceId(f); });
    forEach(ne, [&](std::size_t e) { dirtyElements_[e] = ElementId(e); });
    return;
  }
  faceDirty_.resize(nf, 0);
  elementDirty_.resize(ne, 0);
  for (std::size_t f = oldFaces; f < nf; ++f) invalidateFace(FaceId(f));
  for (std::size_t e = oldElements; e < ne; ++e) invalidateElement(ElementId(e));
}

void MomentCache::reserve(std::size_t faces, std::size_t elements) {
  const std::size_t stride = static_cast<std::size_t>(stride_);
  faceMoments_.reserve(faces * stride);
  elementMoments_.reserve(elements * stride);
  faceNormals_.raw().reserve(faces);
  elementOrigins_.raw().reserve(elements);
  faceDirty_.reserve(faces);
  elementDirty_.reserve(elements);
}

void MomentCache::moveFace(FaceId from, FaceId to) {
  const std::size_t stride = static_cast<std::size_t>(stride_);
  if (from.index() >= faceNormals_.size() || faceDirty_[from.index()]) {
    if (to.index() < faceNormals_.size() && !faceDirty_[to.index()]) {
      faceDirty_[to.index()] = 1;
      dirtyFaces_.push_back(to);
    }
    return;
  }
  std::copy_n(faceMoments_.begin() + from.index() * stride, stride,
              faceMoments_.begin() + to.index() * stride);
  faceNormals_[to] = faceNormals_[from];
  faceDirty_[to.index()] = 0;  // a stale entry in dirtyFaces_ is skipped by update()
}

void MomentCache::moveElement(ElementId from, ElementId to) {
  const std::size_t stride = static_cast<std::size_t>(stride_);
  if (from.index() >= elementOrigins_.size() || elementDirty_[from.index()]) {
    invalidateElement(to);
    return;
  }
  std::copy_n(elementMoments_.begin() + from.index() * stride, stride,
              elementMoments_.begin() + to.index() * stride);
  elementOrigins_[to] = elementOrigins_[from];
  elementDirty_[to.index()] = 0;
}

void MomentCache::reverseFace(FaceId f) {
  if (f.index() < faceNormals_.size()) faceNormals_[f] = -faceNormals_[f];
}

void MomentCache::assignFace(FaceId f, std::span<const double> values, const Vec3& normal) {
  if (values.size() != static_cast<std::size_t>(stride_))
    throw std::invalid_argument("MomentCache::assignFace: moments of another degree");
  std::copy(values.begin(), values.end(), faceMoments_.begin() + f.index() * stride_);
  faceNormals_[f] = normal;
  invalidateFace(f);
  faceDirty_[f.index()] = 0;  // a stale entry in dirtyFaces_ is skipped by update()
}

void MomentCache::invalidateAll() {
  for (std::size_t f = 0; f < faceDirty_.size(); ++f) invalidateFace(FaceId(f));
}

void MomentCache::invalidateFace(FaceId f) {
  if (!faceDirty_[f.index()]) {
    faceDirty_[f.index()] = 1;
    dirtyFaces_.push_back(f);
  }
  const Face& face = mesh_->face(f);
  if (face.front.valid()) invalidateElement(face.front);
  if (face.back.valid()) invalidateElement(face.back);
}

void MomentCache::invalidateElement(ElementId e) {
  if (e.index() >= elementDirty_.size()) return;  // appended later; sync() picks it up
  if (!elementDirty_[e.index()]) {
    elementDirty_[e.index()] = 1;
    dirtyElements_.push_back(e);
  }
}

std::size_t MomentCache::update() {
  const PolyMesh& mesh = *mesh_;
  const std::size_t stride = static_cast<std::size_t>(stride_);
  // Entries may be stale after moves and shrinking: keep each dirty id in range once.
  auto prune = [](auto& list, auto& flags) {
    std::size_t kept = 0;
    for (auto id : list)
      if (id.index() < flags.size() && flags[id.index()] == 1) {
        flags[id.index()] = 2;
        list[kept++] = id;
      }
    list.resize(kept);
    for (auto id : list) flags[id.index()] = 1;
  };
  prune(dirtyFaces_, faceDirty_);
  prune(dirtyElements_, elementDirty_);

  forEach(dirtyFaces_.size(), [&](std::size_t i) {
    const FaceId f = dirtyFaces_[i];
    faceMoments(mesh, f, degree_, {faceMoments_.data() + f.index() * stride, stride},
                faceNormals_[f]);
  });

  forEach(dirtyElements_.size(), [&](std::size_t i) {
    const ElementId e = dirtyElements_[i];
    const Vec3 origin = elementReferencePoint(mesh, e);
    elementOrigins_[e] = origin;
    std::span<double> out{elementMoments_.data() + e.index() * stride, stride};
    std::fill(out.begin(), out.end(), 0.0);
    double scratch[numMonomials(kMaxMomentDegree)];
    for (const FaceUse& use : mesh.element(e).faces) {
      accumulateElementMoments(degree_, face(use.face), faceReferencePoint(mesh, use.face),
                               faceNormals_[use.face], use.reversed, origin, {scratch, stride},
                               out);
    }
  });

  const std::size_t integrated = dirtyFaces_.size();
  facesIntegrated_ += integrated;
  for (FaceId f : dirtyFaces_) faceDirty_[f.index()] = 0;
  for (ElementId e : dirtyElements_) elementDirty_[e.index()] = 0;
  dirtyFaces_.clear();
  dirtyElements_.clear();
  return integrated;
}

Vec3 MomentCache::centroid(ElementId e) const {
  const auto m = element(e);
  if (degree_ < 1) return elementOrigins_[e];
  return elementOrigins_[e] + Vec3(m[1], m[2], m[3]) / m[0];
}

}  // namespace polydg
