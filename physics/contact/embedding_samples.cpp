// Making the samples of the MLS surface embedding (polydg/physics/contact/embedding.h): one
// per mesh vertex and piece (eq. 17), face and element centres for degree 2 and 3, clustered
// where they crowd, and the grids that find elements and samples near a point.
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "physics/contact/embedding_samples.h"
#include "polydg/mesh/geometry.h"
#include "util/union_find.h"

namespace polydg {

/// Merges samples closer than a quarter to a half of their elements' size (cells of 2^L / 2
/// for the level L = floor(log2 scale), per piece): mean position, mean value (an affine field
/// stays exact), largest support. A surface of far more vertices than the mesh's elements
/// otherwise brings as many samples into every point's fit. Members are summed in order of
/// position, so the result does not depend on element numbering.
SurfaceEmbedding::Samples SurfaceEmbedding::clustered(Samples&& raw) {
  struct Key {
    int level;
    std::uint32_t piece;
    std::int64_t i, j, k;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& key) const {
      std::uint64_t h = 1469598103934665603ull;
      for (std::uint64_t v : {static_cast<std::uint64_t>(key.level), std::uint64_t(key.piece),
                              static_cast<std::uint64_t>(key.i), static_cast<std::uint64_t>(key.j),
                              static_cast<std::uint64_t>(key.k)})
        h = (h ^ v) * 1099511628211ull;
      return static_cast<std::size_t>(h);
    }
  };
  const std::size_t count = raw.positions.size();
  std::vector<std::uint32_t> order(count);
  for (std::size_t q = 0; q < count; ++q) order[q] = static_cast<std::uint32_t>(q);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const Vec3 &x = raw.positions[a], &y = raw.positions[b];
    return std::lexicographical_compare(x.data(), x.data() + 3, y.data(), y.data() + 3) ||
           (x == y && raw.piece[a] < raw.piece[b]);
  });
  std::unordered_map<Key, std::uint32_t, KeyHash> clusterOf;
  std::vector<std::vector<std::uint32_t>> members;
  for (std::uint32_t q : order) {
    // radius = support * scale; the level of the scale itself.
    const double scale = raw.radius[q];
    const int level = static_cast<int>(std::floor(std::log2(scale)));
    const double cell = std::ldexp(1.0, level) / 4.0;  // radius / 4..8: scale / 2..4 at support 2
    const Vec3& x = raw.positions[q];
    const Key key{level, raw.piece[q], static_cast<std::int64_t>(std::floor(x.x() / cell)),
                  static_cast<std::int64_t>(std::floor(x.y() / cell)),
                  static_cast<std::int64_t>(std::floor(x.z() / cell))};
    const auto [it, added] = clusterOf.emplace(key, static_cast<std::uint32_t>(members.size()));
    if (added) members.emplace_back();
    members[it->second].push_back(q);
  }
  SurfaceEmbedding::Samples out;
  out.numPieces = raw.numPieces;
  out.elementPiece = std::move(raw.elementPiece);
  out.constant = std::move(raw.constant);
  out.boxes = std::move(raw.boxes);
  out.largestRadius = raw.largestRadius;
  std::vector<std::pair<std::uint32_t, double>> row;
  for (const auto& group : members) {
    Vec3 x = Vec3::Zero();
    double radius = 0.0;
    const double w = 1.0 / static_cast<double>(group.size());
    row.clear();
    for (std::uint32_t q : group) {
      x += raw.positions[q];
      radius = std::max(radius, raw.radius[q]);
      for (std::size_t r = raw.start[q]; r < raw.start[q + 1]; ++r)
        row.emplace_back(raw.columns[r], w * raw.values[r]);
    }
    out.positions.push_back(group.size() == 1 ? raw.positions[group.front()] : Vec3(x * w));
    out.radius.push_back(radius);
    out.piece.push_back(raw.piece[group.front()]);
    out.addRow(row);
  }
  return out;
}

SurfaceEmbedding::Samples SurfaceEmbedding::makeSamples(const PolyMesh& mesh,
                                                        const DgBasis& basis) const {
  Samples s;
  const std::size_t ne = mesh.numElements();
  const int n = basis.size();
  // Pieces: elements joined through interior faces; a cut leaves its two sides apart.
  UnionFind groups(ne);
  for (const Face& f : mesh.faces())
    if (f.front.valid() && f.back.valid()) groups.unite(f.front.value, f.back.value);
  s.elementPiece.resize(ne);
  s.constant.resize(ne);
  // The scaled monomials start with 1, so phi_0 = T[0][0] everywhere in the element.
  for (std::size_t e = 0; e < ne; ++e) s.constant[e] = basis.coefficients(ElementId(e))(0, 0);
  {
    std::unordered_map<std::uint32_t, std::uint32_t> label;
    for (std::size_t e = 0; e < ne; ++e) {
      const auto root = groups.find(static_cast<std::uint32_t>(e));
      const auto [it, added] = label.emplace(root, static_cast<std::uint32_t>(label.size()));
      s.elementPiece[e] = it->second;
    }
    s.numPieces = label.size();
  }
  std::vector<double> phi(static_cast<std::size_t>(n));
  std::vector<std::pair<std::uint32_t, double>> row;
  auto addValues = [&](ElementId e, const Vec3& x, double w) {
    basis.values(e, x, phi);
    for (int i = 0; i < n; ++i)
      row.emplace_back(static_cast<std::uint32_t>(e.index() * static_cast<std::size_t>(n) + i),
                       w * phi[static_cast<std::size_t>(i)]);
  };
  auto addSample = [&](const Vec3& x, std::uint32_t piece, double scale) {
    s.positions.push_back(x);
    s.piece.push_back(piece);
    s.radius.push_back(options_.support * scale);
    s.largestRadius = std::max(s.largestRadius, s.radius.back());
    s.addRow(row);
    row.clear();
  };

  // Vertex samples, one per (vertex, piece): eq. (17) over the piece's elements.
  std::unordered_map<std::uint64_t, std::uint32_t>& vertexSample = s.vertexSample;
  std::vector<std::vector<std::uint32_t>> sampleElements;
  s.boxes.resize(ne);
  for (std::size_t e = 0; e < ne; ++e) {
    s.boxes[e] = elementBounds(mesh, ElementId(e));
    for (VertexId v : elementVertices(mesh, ElementId(e))) {
      const std::uint64_t key = (static_cast<std::uint64_t>(v.value) << 32) | s.elementPiece[e];
      const auto [it, added] =
          vertexSample.emplace(key, static_cast<std::uint32_t>(sampleElements.size()));
      if (added) sampleElements.emplace_back();
      sampleElements[it->second].push_back(static_cast<std::uint32_t>(e));
      s.elementSamples.push_back(it->second);
    }
    s.elementSampleStart.push_back(s.elementSamples.size());
  }
  std::vector<Vec3> vertexOf(sampleElements.size());
  for (const auto& [key, id] : vertexSample) vertexOf[id] = mesh.position(VertexId(key >> 32));
  for (std::size_t k = 0; k < sampleElements.size(); ++k) {
    const auto& elements = sampleElements[k];
    double scale = 0.0;
    for (std::uint32_t e : elements) {
      addValues(ElementId(e), vertexOf[k], 1.0 / static_cast<double>(elements.size()));
      scale = std::max(scale, basis.scale(ElementId(e)));
    }
    addSample(vertexOf[k], s.elementPiece[elements.front()], scale);
  }
  // Degree 2 and 3: face and element centres follow the higher-order field.
  if (basis.degree() >= 2) {
    for (std::size_t f = 0; f < mesh.numFaces(); ++f) {
      const Face& face = mesh.face(FaceId(f));
      Vec3 c = Vec3::Zero();
      for (VertexId v : face.vertices) c += mesh.position(v);
      c /= static_cast<double>(face.vertices.size());
      const double w = face.back.valid() ? 0.5 : 1.0;
      addValues(face.front, c, w);
      double scale = basis.scale(face.front);
      if (face.back.valid()) {
        addValues(face.back, c, w);
        scale = std::max(scale, basis.scale(face.back));
      }
      addSample(c, s.elementPiece[face.front.index()], scale);
    }
    for (std::size_t e = 0; e < ne; ++e) {
      const ElementId id(e);
      addValues(id, basis.centre(id), 1.0);
      addSample(basis.centre(id), s.elementPiece[e], basis.scale(id));
    }
  }

  if (options_.method == EmbeddingMethod::Mls) s = clustered(std::move(s));

  Box3 all;
  for (const Box3& b : s.boxes) all.extend(b);
  for (const Vec3& x : s.positions) all.extend(x);
  double meanSide = 0.0;
  for (const Box3& b : s.boxes) meanSide += b.sizes().maxCoeff();
  meanSide = ne > 0 ? meanSide / static_cast<double>(ne) : 1.0;
  if (!(meanSide > 0.0)) meanSide = 1.0;
  s.elementGrid = HashGrid(all, meanSide);
  for (std::size_t e = 0; e < ne; ++e)
    s.elementGrid.insert(s.boxes[e], static_cast<std::uint32_t>(e));
  s.sampleGrid = HashGrid(all, s.largestRadius > 0.0 ? s.largestRadius : meanSide);
  for (std::size_t k = 0; k < s.positions.size(); ++k)
    s.sampleGrid.insert(s.positions[k], static_cast<std::uint32_t>(k));
  return s;
}

}  // namespace polydg
