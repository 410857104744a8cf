// Penalty contact on embedded points (physics/contact/contact.h).
#include "physics/contact/contact.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "util/stopwatch.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Triplets = std::vector<Eigen::Triplet<double, int>>;

}  // namespace

ContactModel::ContactModel(const SurfaceEmbedding& points, std::vector<double> areas,
                           std::vector<Obstacle> obstacles, const ContactOptions& options)
    : embedding_(&points),
      areas_(std::move(areas)),
      obstacles_(std::move(obstacles)),
      options_(options) {
  if (!(options_.stiffness > 0.0) || !std::isfinite(options_.stiffness))
    throw std::invalid_argument("the contact stiffness must be a positive number");
  if (!(options_.friction >= 0.0) || !std::isfinite(options_.friction))
    throw std::invalid_argument("the friction coefficient must not be negative");
  if (options_.friction > 0.0 &&
      (!(options_.slipSpeed > 0.0) || !std::isfinite(options_.slipSpeed)))
    throw std::invalid_argument("friction needs a positive slip speed");
  if (options_.maxPasses < 1) throw std::invalid_argument("contact passes must be at least 1");
  if (areas_.size() != points.numPoints())
    throw std::invalid_argument("ContactModel: one area per point");
  refresh();
}

void ContactModel::refresh() {
  const SurfaceEmbedding& e = *embedding_;
  if (areas_.size() != e.numPoints())
    throw std::invalid_argument("ContactModel: the embedding's points changed; make it again");
  dofs_ = e.numElements() * 3 * static_cast<std::size_t>(e.basisSize());
  active_.clear();
  cachedCoefficients_.resize(0);
}

const Eigen::Matrix<double, Eigen::Dynamic, 3>& ContactModel::displacementsOf(
    const Eigen::VectorXd& u) {
  // A step's end state is measured, then linearized about at the next step's start: the same
  // coefficients, one surface update.
  if (cachedCoefficients_.size() != u.size() || cachedCoefficients_ != u) {
    cachedDisplacement_ = embedding_->displacements(u);
    cachedCoefficients_ = u;
  }
  return cachedDisplacement_;
}

Eigen::Matrix<double, Eigen::Dynamic, 3> ContactModel::positionsOf(
    const Eigen::Matrix<double, Eigen::Dynamic, 3>& displacement) const {
  Eigen::Matrix<double, Eigen::Dynamic, 3> x(displacement.rows(), 3);
  for (std::size_t p = 0; p < embedding_->numPoints(); ++p)
    x.row(static_cast<Eigen::Index>(p)) =
        embedding_->points()[p].transpose() + displacement.row(static_cast<Eigen::Index>(p));
  return x;
}

ContactModel::Active ContactModel::contact(std::size_t point, std::uint32_t obstacle,
                                           const ObstacleQuery& q,
                                           const Eigen::Matrix<double, Eigen::Dynamic, 3>& at) {
  Active a;
  a.point = static_cast<std::uint32_t>(point);
  a.obstacle = obstacle;
  a.distance = q.distance;
  a.normal = q.normal;
  a.position = at.row(static_cast<Eigen::Index>(point)).transpose();
  return a;
}

double ContactModel::takeQuerySeconds() {
  const double s = querySeconds_;
  querySeconds_ = 0.0;
  return s;
}

void ContactModel::queryAll(const Eigen::Matrix<double, Eigen::Dynamic, 3>& positions, double t,
                            std::vector<ObstacleQuery>& out, std::vector<std::uint32_t>& which) {
  const std::size_t np = static_cast<std::size_t>(positions.rows());
  out.assign(np, ObstacleQuery{std::numeric_limits<double>::infinity(), Vec3::Zero()});
  which.assign(np, 0);
  std::vector<Vec3> inside;
  std::vector<std::uint32_t> index;
  std::vector<ObstacleQuery> answers;
  for (std::size_t o = 0; o < obstacles_.size(); ++o) {
    const Box3 box = obstacles_[o].bounds(t);
    inside.clear();
    index.clear();
    for (std::size_t p = 0; p < np; ++p) {
      const Vec3 x = positions.row(static_cast<Eigen::Index>(p)).transpose();
      if (box.contains(x)) {
        inside.push_back(x);
        index.push_back(static_cast<std::uint32_t>(p));
      }
    }
    answers.resize(inside.size());
    obstacles_[o].query(inside, t, answers);
    for (std::size_t k = 0; k < index.size(); ++k)
      if (answers[k].distance < out[index[k]].distance) {
        out[index[k]] = answers[k];
        which[index[k]] = static_cast<std::uint32_t>(o);
      }
  }
}

ContactLinearization ContactModel::linearize(const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                                             double tNext, double dt) {
  const Stopwatch watch;
  const SurfaceEmbedding& e = *embedding_;
  tNext_ = tNext;
  startDisplacement_ = displacementsOf(u);
  const Eigen::Matrix<double, Eigen::Dynamic, 3> velocity = e.displacements(v);
  const std::size_t np = e.numPoints();
  const Eigen::Matrix<double, Eigen::Dynamic, 3> predicted =
      positionsOf(startDisplacement_ + dt * velocity);
  std::vector<ObstacleQuery> q;
  std::vector<std::uint32_t> which;
  queryAll(predicted, tNext, q, which);
  active_.clear();
  for (std::size_t p = 0; p < np; ++p) {
    if (!(q[p].distance < 0.0) || q[p].normal.isZero()) continue;
    Active a = contact(p, which[p], q[p], predicted);
    const Vec3 relative =
        velocity.row(static_cast<Eigen::Index>(p)).transpose() - obstacles_[which[p]].velocity();
    a.slip = relative - a.normal * a.normal.dot(relative);
    active_.push_back(a);
  }
  querySeconds_ += watch.seconds();
  return build();
}

bool ContactModel::adjust(const Eigen::VectorXd& uNew) {
  const Stopwatch watch;
  const SurfaceEmbedding& e = *embedding_;
  const Eigen::Matrix<double, Eigen::Dynamic, 3>& disp = displacementsOf(uNew);
  const std::size_t np = e.numPoints();
  bool changed = false;
  // Drop contacts whose linearized force pulls at the new state.
  std::vector<char> isActive(np, 0);
  std::vector<Active> kept;
  for (const Active& a : active_) {
    const Vec3 x = e.points()[a.point];
    const Vec3 y = x + disp.row(a.point).transpose();
    if (a.distance + a.normal.dot(y - a.position) > 0.0) {
      changed = true;
      continue;
    }
    kept.push_back(a);
    isActive[a.point] = 1;
  }
  // Add points that end inside an obstacle.
  const Eigen::Matrix<double, Eigen::Dynamic, 3> positions = positionsOf(disp);
  std::vector<ObstacleQuery> q;
  std::vector<std::uint32_t> which;
  queryAll(positions, tNext_, q, which);
  for (std::size_t p = 0; p < np; ++p) {
    if (isActive[p] || !(q[p].distance < 0.0) || q[p].normal.isZero()) continue;
    kept.push_back(contact(p, which[p], q[p], positions));  // no slip yet: full friction
    changed = true;
  }
  active_ = std::move(kept);
  querySeconds_ += watch.seconds();
  return changed;
}

ContactLinearization ContactModel::relinearize() { return build(); }

ContactLinearization ContactModel::build() const {
  const SurfaceEmbedding& e = *embedding_;
  const std::size_t n = static_cast<std::size_t>(e.basisSize());
  ContactLinearization out;
  out.contacts = active_.size();
  out.force = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dofs_));
  if (active_.empty()) return out;
  // The coefficients the active points move: a compact numbering of their W columns.
  std::unordered_map<std::uint32_t, std::uint32_t> local;
  std::vector<std::uint32_t> columns;
  for (const Active& a : active_)
    for (std::uint32_t c : e.weightRow(a.point).columns)
      if (local.emplace(c, static_cast<std::uint32_t>(columns.size())).second) columns.push_back(c);
  auto dof = [&](std::uint32_t column, int d) {
    const std::size_t el = column / n, i = column % n;
    return static_cast<Eigen::Index>((el * 3 + static_cast<std::size_t>(d)) * n + i);
  };
  // K_c = G G^T with one column sqrt(k a) (W_c (x) n) per contact; C_t = H H^T with two
  // columns sqrt(c_t) (W_c (x) t_1,2) per contact with friction: dense over the compact
  // coefficients, rank-one updates done by one matrix product.
  const Eigen::Index m = static_cast<Eigen::Index>(3 * columns.size());
  const Eigen::Index contacts = static_cast<Eigen::Index>(active_.size());
  const bool friction = options_.friction > 0.0;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(m, contacts);
  Eigen::MatrixXd h = friction ? Eigen::MatrixXd::Zero(m, 2 * contacts) : Eigen::MatrixXd();
  for (Eigen::Index k = 0; k < contacts; ++k) {
    const Active& a = active_[static_cast<std::size_t>(k)];
    const double ka = options_.stiffness * areas_[a.point];
    const SparseRow row = e.weightRow(a.point);
    const Vec3 uStart = startDisplacement_.row(a.point).transpose();
    // f(U_n) = -k a (phi(q) + n . (u~_n - u~_q)) n, u~_q = q - x.
    const double gap = a.distance + a.normal.dot(e.points()[a.point] + uStart - a.position);
    Vec3 force = -ka * gap * a.normal;
    double ct = 0.0;
    Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero();
    if (friction) {
      // Regularized Coulomb: c_t = mu |f| / max(|slip|, v_s); the obstacle's own velocity
      // enters as the constant part of -c_t (I - n n^T)(v~ - v_obstacle).
      ct = options_.friction * ka * std::abs(a.distance) /
           std::max(a.slip.norm(), options_.slipSpeed);
      t1 = a.normal.unitOrthogonal();
      t2 = a.normal.cross(t1);
      const Vec3 vo = obstacles_[a.obstacle].velocity();
      force += ct * (vo - a.normal * a.normal.dot(vo));
    }
    const double sk = std::sqrt(ka), sc = std::sqrt(ct);
    for (std::size_t j = 0; j < row.columns.size(); ++j) {
      const Eigen::Index base = 3 * static_cast<Eigen::Index>(local.at(row.columns[j]));
      const double w = row.values[j];
      for (int d = 0; d < 3; ++d) {
        g(base + d, k) = sk * w * a.normal[d];
        if (friction) {
          h(base + d, 2 * k) = sc * w * t1[d];
          h(base + d, 2 * k + 1) = sc * w * t2[d];
        }
        out.force[dof(row.columns[j], d)] += w * force[d];
      }
    }
  }
  auto scatter = [&](const Eigen::MatrixXd& product) {
    Triplets t;
    t.reserve(static_cast<std::size_t>(m * m));
    for (Eigen::Index j = 0; j < m; ++j)
      for (Eigen::Index i = 0; i < m; ++i)
        if (product(i, j) != 0.0)
          t.emplace_back(static_cast<int>(dof(columns[static_cast<std::size_t>(i / 3)],
                                              static_cast<int>(i % 3))),
                         static_cast<int>(dof(columns[static_cast<std::size_t>(j / 3)],
                                              static_cast<int>(j % 3))),
                         product(i, j));
    SpMat result(static_cast<int>(dofs_), static_cast<int>(dofs_));
    result.setFromTriplets(t.begin(), t.end());
    return result;
  };
  const Eigen::MatrixXd kc = g * g.transpose();
  out.stiffness = scatter(kc);
  if (friction) {
    const Eigen::MatrixXd ctm = h * h.transpose();
    out.damping = scatter(ctm);
  }
  return out;
}

ContactMeasure ContactModel::measure(const Eigen::VectorXd& u, double t) {
  const Stopwatch watch;
  const Eigen::Matrix<double, Eigen::Dynamic, 3> positions = positionsOf(displacementsOf(u));
  std::vector<ObstacleQuery> q;
  std::vector<std::uint32_t> which;
  queryAll(positions, t, q, which);
  ContactMeasure m;
  for (std::size_t p = 0; p < q.size(); ++p) {
    if (!(q[p].distance < 0.0)) continue;
    ++m.contacts;
    m.deepest = std::max(m.deepest, -q[p].distance);
    m.energy += 0.5 * options_.stiffness * areas_[p] * q[p].distance * q[p].distance;
  }
  querySeconds_ += watch.seconds();
  return m;
}

}  // namespace polydg
