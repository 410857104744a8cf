#include "physics/fem/tet_discretization.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>

#include <Eigen/Geometry>

#include "integrate/quadrature.h"
#include "physics/dynamics/corotation.h"

namespace polydg {

namespace {

/// The face of tet t opposite its corner k, by its sorted corners.
struct TetFace {
  std::array<std::uint32_t, 3> key;
  std::uint32_t tet;
  int opposite;
};

}  // namespace

TetDiscretization::TetDiscretization(const TetMesh& mesh, TetMethod method)
    : method_(method), numNodes_(mesh.numVertices()), tets_(mesh.tets) {
  const std::size_t nt = mesh.numTets();
  tetVolumes_.resize(nt);
  tetGradients_.resize(nt);
  restEdgesInverse_.resize(nt);
  rest_.resize(static_cast<Eigen::Index>(3 * numNodes_));
  for (std::size_t v = 0; v < numNodes_; ++v) rest_.segment<3>(3 * v) = mesh.vertices[v];
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& c = tets_[t];
    const Vec3& x0 = mesh.vertices[c[0]];
    Eigen::Matrix3d edges;  // columns X1 - X0, X2 - X0, X3 - X0
    for (int k = 0; k < 3; ++k) edges.col(k) = mesh.vertices[c[k + 1]] - x0;
    const double det = edges.determinant();
    if (!(det > 0.0))
      throw std::invalid_argument("tet " + std::to_string(t) +
                                  " has no positive volume; the tet methods need valid tets");
    tetVolumes_[t] = det / 6.0;
    const Eigen::Matrix3d inverse = edges.inverse();
    restEdgesInverse_[t] = inverse;
    // Node a's shape function is the a-th barycentric coordinate: rows of the inverse.
    tetGradients_[t].bottomRows<3>() = inverse;
    tetGradients_[t].row(0) = -inverse.colwise().sum();
  }

  if (method == TetMethod::Fem) {
    domains_.resize(nt);
    for (std::size_t t = 0; t < nt; ++t) {
      StrainDomain& d = domains_[t];
      d.numNodes = 4;
      for (int a = 0; a < 4; ++a) d.nodes[a] = tets_[t][a];
      d.numTets = 1;
      d.tets[0] = static_cast<std::uint32_t>(t);
      d.tetVolume[0] = d.volume = tetVolumes_[t];
      d.gradients.topRows<4>() = tetGradients_[t];
    }
    return;
  }

  // FS-FEM: the faces, each from its one or two tets.
  std::vector<TetFace> faces;
  faces.reserve(4 * nt);
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) {
      TetFace f{{}, static_cast<std::uint32_t>(t), k};
      int i = 0;
      for (int j = 0; j < 4; ++j)
        if (j != k) f.key[i++] = tets_[t][j];
      std::sort(f.key.begin(), f.key.end());
      faces.push_back(f);
    }
  std::sort(faces.begin(), faces.end(), [](const TetFace& a, const TetFace& b) {
    return std::tie(a.key, a.tet) < std::tie(b.key, b.tet);
  });
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i > 2)
      throw std::invalid_argument(
          "a face is shared by more than two tets; the mesh is not "
          "conforming");
    StrainDomain d;
    d.numNodes = 3;
    for (int a = 0; a < 3; ++a) d.nodes[a] = faces[i].key[a];
    for (std::size_t s = i; s < j; ++s) {
      const std::uint32_t t = faces[s].tet;
      d.nodes[d.numNodes++] = tets_[t][faces[s].opposite];
      d.tets[d.numTets] = t;
      d.tetVolume[d.numTets] = tetVolumes_[t] / 4.0;
      d.volume += d.tetVolume[d.numTets];
      ++d.numTets;
    }
    // The volume-weighted mean of the tets' gradients, node by node.
    for (int s = 0; s < d.numTets; ++s) {
      const std::uint32_t t = d.tets[s];
      const double weight = d.tetVolume[s] / d.volume;
      for (int a = 0; a < 4; ++a) {
        const int row =
            static_cast<int>(std::find(d.nodes.begin(), d.nodes.begin() + d.numNodes, tets_[t][a]) -
                             d.nodes.begin());
        d.gradients.row(row) += weight * tetGradients_[t].row(a);
      }
    }
    domains_.push_back(d);
    i = j;
  }
}

Eigen::MatrixXd TetDiscretization::domainStiffness(const StrainDomain& d,
                                                   const Material& material) const {
  const double lambda = material.lambda(), mu = material.mu();
  const int n = d.numNodes;
  Eigen::MatrixXd k(3 * n, 3 * n);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const Eigen::RowVector3d ga = d.gradients.row(a), gb = d.gradients.row(b);
      k.block<3, 3>(3 * a, 3 * b) =
          d.volume * (lambda * ga.transpose() * gb + mu * gb.transpose() * ga +
                      mu * ga.dot(gb) * Eigen::Matrix3d::Identity());
    }
  return k;
}

namespace {

void addBlocks(const StrainDomain& d, const Eigen::MatrixXd& block,
               std::vector<Eigen::Triplet<double>>& triplets) {
  for (int a = 0; a < d.numNodes; ++a)
    for (int b = 0; b < d.numNodes; ++b)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          triplets.emplace_back(static_cast<int>(3 * d.nodes[a]) + i,
                                static_cast<int>(3 * d.nodes[b]) + j, block(3 * a + i, 3 * b + j));
}

}  // namespace

Eigen::SparseMatrix<double> TetDiscretization::stiffness(const Material& material) const {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(domains_.size() * 225);
  for (const StrainDomain& d : domains_) addBlocks(d, domainStiffness(d, material), triplets);
  const auto n = static_cast<Eigen::Index>(numDofs());
  Eigen::SparseMatrix<double> k(n, n);
  k.setFromTriplets(triplets.begin(), triplets.end());
  return k;
}

void TetDiscretization::corotatedStiffness(const Material& material,
                                           const std::vector<Eigen::Matrix3d>& rotations,
                                           Eigen::SparseMatrix<double>& k,
                                           Eigen::VectorXd& offset) const {
  if (rotations.size() != domains_.size())
    throw std::invalid_argument("corotatedStiffness needs one rotation per domain");
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(domains_.size() * 225);
  offset = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(numDofs()));
  for (std::size_t i = 0; i < domains_.size(); ++i) {
    const StrainDomain& d = domains_[i];
    const int n = d.numNodes;
    const Eigen::MatrixXd kd = domainStiffness(d, material);
    Eigen::MatrixXd r = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    Eigen::VectorXd rest(3 * n);
    for (int a = 0; a < n; ++a) {
      r.block<3, 3>(3 * a, 3 * a) = rotations[i];
      rest.segment<3>(3 * a) = rest_.segment<3>(3 * d.nodes[a]);
    }
    const Eigen::MatrixXd rk = r * kd;
    addBlocks(d, rk * r.transpose(), triplets);
    const Eigen::VectorXd f = rk * rest;
    for (int a = 0; a < n; ++a) offset.segment<3>(3 * d.nodes[a]) += f.segment<3>(3 * a);
  }
  const auto nd = static_cast<Eigen::Index>(numDofs());
  k.resize(nd, nd);
  k.setFromTriplets(triplets.begin(), triplets.end());
}

std::vector<Eigen::Matrix3d> TetDiscretization::tetRotations(const Eigen::VectorXd& x) const {
  std::vector<Eigen::Matrix3d> out(tets_.size());
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    const auto& c = tets_[t];
    Eigen::Matrix3d edges;
    for (int k = 0; k < 3; ++k) edges.col(k) = x.segment<3>(3 * c[k + 1]) - x.segment<3>(3 * c[0]);
    out[t] = polarRotation(edges * restEdgesInverse_[t]);
  }
  return out;
}

std::vector<Eigen::Matrix3d> TetDiscretization::domainRotations(
    const std::vector<Eigen::Matrix3d>& tetRotations) const {
  std::vector<Eigen::Matrix3d> out(domains_.size());
  for (std::size_t i = 0; i < domains_.size(); ++i) {
    const StrainDomain& d = domains_[i];
    if (d.numTets == 1) {
      out[i] = tetRotations[d.tets[0]];
      continue;
    }
    const Eigen::Quaterniond q0(tetRotations[d.tets[0]]), q1(tetRotations[d.tets[1]]);
    out[i] = q0.slerp(d.tetVolume[1] / d.volume, q1).toRotationMatrix();
  }
  return out;
}

std::vector<double> TetDiscretization::tetVonMises(const Eigen::VectorXd& x,
                                                   const Material& material,
                                                   bool corotational) const {
  std::vector<double> out(tets_.size());
  const double lambda = material.lambda(), mu = material.mu();
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    const auto& c = tets_[t];
    Eigen::Matrix3d edges;
    for (int k = 0; k < 3; ++k) edges.col(k) = x.segment<3>(3 * c[k + 1]) - x.segment<3>(3 * c[0]);
    Eigen::Matrix3d f = edges * restEdgesInverse_[t];
    if (corotational) f = polarRotation(f).transpose() * f;
    const Eigen::Matrix3d strain = 0.5 * (f + f.transpose()) - Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d stress =
        lambda * strain.trace() * Eigen::Matrix3d::Identity() + 2.0 * mu * strain;
    const Eigen::Matrix3d deviator = stress - stress.trace() / 3.0 * Eigen::Matrix3d::Identity();
    out[t] = std::sqrt(1.5 * deviator.squaredNorm());
  }
  return out;
}

double TetDiscretization::volume(const Eigen::VectorXd& x) const {
  double six = 0.0;
  for (const auto& c : tets_) {
    const Eigen::Vector3d o = x.segment<3>(3 * c[0]);
    six += (x.segment<3>(3 * c[1]) - o)
               .dot((x.segment<3>(3 * c[2]) - o).cross(x.segment<3>(3 * c[3]) - o));
  }
  return six / 6.0;
}

Eigen::VectorXd TetDiscretization::lumpedMass(double density) const {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(numDofs()));
  for (std::size_t t = 0; t < tets_.size(); ++t)
    for (std::uint32_t v : tets_[t]) m.segment<3>(3 * v).array() += density * tetVolumes_[t] / 4.0;
  return m;
}

Eigen::VectorXd TetDiscretization::bodyForceLoad(const Eigen::Vector3d& force) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(numDofs()));
  for (std::size_t t = 0; t < tets_.size(); ++t)
    for (std::uint32_t v : tets_[t]) f.segment<3>(3 * v) += force * (tetVolumes_[t] / 4.0);
  return f;
}

Eigen::VectorXd TetDiscretization::bodyForceFieldLoad(
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& force) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(numDofs()));
  std::vector<QuadraturePoint> rule;
  for (std::size_t t = 0; t < tets_.size(); ++t) {
    const auto& c = tets_[t];
    const Eigen::Vector3d x0 = rest_.segment<3>(3 * c[0]);
    rule.clear();
    appendTetrahedronRule(x0, rest_.segment<3>(3 * c[1]), rest_.segment<3>(3 * c[2]),
                          rest_.segment<3>(3 * c[3]), 2, rule);
    for (const QuadraturePoint& q : rule) {
      // The shape functions at q: its barycentric coordinates.
      const Eigen::Vector3d xi = restEdgesInverse_[t] * (q.point - x0);
      const Eigen::Vector4d shape(1.0 - xi.sum(), xi.x(), xi.y(), xi.z());
      const Eigen::Vector3d value = q.weight * force(q.point);
      for (int k = 0; k < 4; ++k) f.segment<3>(3 * c[k]) += shape[k] * value;
    }
  }
  return f;
}

}  // namespace polydg
