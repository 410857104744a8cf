// Penalty contact on embedded points (physics/contact/contact.h).
#include "physics/contact/contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "util/stopwatch.h"

namespace polydg {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Triplets = std::vector<Eigen::Triplet<double, int>>;

/// Contacts grouped by their exact normal: contact k is member slot[k] of group group[k].
struct NormalGroups {
  std::vector<Eigen::Index> group, slot, size;
  std::vector<Vec3> normal;
};

NormalGroups groupByNormal(const std::vector<Vec3>& normals) {
  std::map<std::array<double, 3>, std::vector<Eigen::Index>> byNormal;
  for (std::size_t k = 0; k < normals.size(); ++k)
    byNormal[{normals[k].x(), normals[k].y(), normals[k].z()}].push_back(
        static_cast<Eigen::Index>(k));
  NormalGroups g;
  g.group.resize(normals.size());
  g.slot.resize(normals.size());
  for (const auto& [normal, members] : byNormal) {
    for (std::size_t i = 0; i < members.size(); ++i) {
      g.group[static_cast<std::size_t>(members[i])] = static_cast<Eigen::Index>(g.normal.size());
      g.slot[static_cast<std::size_t>(members[i])] = static_cast<Eigen::Index>(i);
    }
    g.normal.emplace_back(normal[0], normal[1], normal[2]);
    g.size.push_back(static_cast<Eigen::Index>(members.size()));
  }
  return g;
}

/// to += scalar (x) b: scalar's entry (i, j) times b in the 3 x 3 block (i, j).
void addKronecker(const Eigen::MatrixXd& scalar, const Eigen::Matrix3d& b, Eigen::MatrixXd& to) {
  for (Eigen::Index j = 0; j < scalar.cols(); ++j)
    for (Eigen::Index i = 0; i < scalar.rows(); ++i)
      if (scalar(i, j) != 0.0) to.block<3, 3>(3 * i, 3 * j) += scalar(i, j) * b;
}

/// Row p of W: its nonzero weights and their scalar coefficient columns e * n + i, ascending.
struct WeightRow {
  std::vector<std::uint32_t> columns;
  std::vector<double> values;
};
WeightRow weightRow(const SurfaceEmbedding& e, std::size_t p) {
  const WeightBlocks blocks = e.weightBlocks(p);
  const std::size_t n = static_cast<std::size_t>(e.basisSize());
  WeightRow row;
  for (std::size_t k = 0; k < blocks.elements.size(); ++k)
    for (std::size_t i = 0; i < n; ++i)
      if (const double w = blocks.values[k * n + i]; w != 0.0) {
        row.columns.push_back(static_cast<std::uint32_t>(blocks.elements[k] * n + i));
        row.values.push_back(w);
      }
  return row;
}

/// f(k) for k = 0 .. count - 1 on both cores: a point's position is a sparse row of about a
/// hundred weights, and a resting body has thousands of candidate points each pass.
template <class F>
void forEachPoint(std::size_t count, const F& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k != r.end(); ++k) f(k);
                    });
}

/// The rows of W of `points` and a compact numbering of the columns they reach: columns[local[c]]
/// is c, in order of first appearance.
std::tuple<std::vector<WeightRow>, std::unordered_map<std::uint32_t, std::uint32_t>,
           std::vector<std::uint32_t>>
rowsAndColumns(const SurfaceEmbedding& e, const std::vector<std::uint32_t>& points) {
  std::vector<WeightRow> rows(points.size());
  forEachPoint(points.size(), [&](std::size_t k) { rows[k] = weightRow(e, points[k]); });
  std::unordered_map<std::uint32_t, std::uint32_t> local;
  std::vector<std::uint32_t> columns;
  for (const WeightRow& row : rows)
    for (std::uint32_t c : row.columns)
      if (local.emplace(c, static_cast<std::uint32_t>(columns.size())).second) columns.push_back(c);
  return {std::move(rows), std::move(local), std::move(columns)};
}

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
  const std::size_t np = e.numPoints();
  isActive_.assign(np, 0);
  rowScale_.assign(np, 0.0);
  translationGain_.assign(np, 0.0);
  const std::vector<double>& constant = e.constantValues();
  const std::size_t n = static_cast<std::size_t>(e.basisSize());
  double extent = 0.0;
  for (std::size_t p = 0; p < np; ++p) {
    const WeightBlocks row = e.weightBlocks(p);
    double sum = 0.0, gain = 0.0;
    for (std::size_t k = 0; k < row.elements.size(); ++k) {
      for (std::size_t i = 0; i < n; ++i) sum += std::abs(row.values[k * n + i]);
      gain += row.values[k * n] / constant[row.elements[k]];
    }
    rowScale_[p] = std::sqrt(3.0) * sum;
    translationGain_[p] = gain;
    extent = std::max(extent, e.points()[p].cwiseAbs().maxCoeff());
  }
  maxObstacleSpeed_ = 0.0;
  for (const Obstacle& o : obstacles_)
    maxObstacleSpeed_ = std::max(maxObstacleSpeed_, o.velocity().norm());
  pad_ = 1e-9 * (1.0 + extent);
  clearanceU_.resize(0);  // measured again at the next use
  knownU_.resize(0);
  knownDisplacement_.assign(np, Vec3::Zero());
  known_.assign(np, 0);
  knownStamp_ = 0;
}

double ContactModel::takeQuerySeconds() {
  const double s = querySeconds_;
  querySeconds_ = 0.0;
  return s;
}

void ContactModel::queryAll(const std::vector<Vec3>& positions, double t,
                            std::vector<ObstacleQuery>& out, std::vector<std::uint32_t>& which) {
  const std::size_t np = positions.size();
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
      if (box.contains(positions[p])) {
        inside.push_back(positions[p]);
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

void ContactModel::measureClearances(const Eigen::VectorXd& u, double t) {
  const SurfaceEmbedding& e = *embedding_;
  const std::size_t np = e.numPoints();
  const Eigen::Matrix<double, Eigen::Dynamic, 3> d = e.displacements(u);
  std::vector<Vec3> x(np);
  for (std::size_t p = 0; p < np; ++p)
    x[p] = e.points()[p] + d.row(static_cast<Eigen::Index>(p)).transpose();
  clearance_.assign(np, std::numeric_limits<double>::infinity());
  std::vector<ObstacleQuery> q(np);
  for (const Obstacle& o : obstacles_) {
    if (o.isHalfSpace()) {
      o.query(x, t, q);  // exact distance
      for (std::size_t p = 0; p < np; ++p) clearance_[p] = std::min(clearance_[p], q[p].distance);
      continue;
    }
    const Box3 box = o.bounds(t);
    for (std::size_t p = 0; p < np; ++p) {
      const Vec3 outside = (box.min() - x[p]).cwiseMax(x[p] - box.max()).cwiseMax(Vec3::Zero());
      clearance_[p] = std::min(clearance_[p], outside.norm());
    }
  }
  clearanceU_ = u;
  clearanceT_ = t;
  ++clearanceMeasurements_;
}

std::pair<Vec3, double> ContactModel::translationAndRest(const Eigen::VectorXd& change) const {
  const std::vector<double>& constant = embedding_->constantValues();
  const std::size_t n = static_cast<std::size_t>(embedding_->basisSize());
  const std::size_t ne = constant.size();
  Vec3 low = Vec3::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (std::size_t el = 0; el < ne; ++el)
    for (std::size_t d = 0; d < 3; ++d) {
      const double mean = change[static_cast<Eigen::Index>((el * 3 + d) * n)] * constant[el];
      low[static_cast<Eigen::Index>(d)] = std::min(low[static_cast<Eigen::Index>(d)], mean);
      high[static_cast<Eigen::Index>(d)] = std::max(high[static_cast<Eigen::Index>(d)], mean);
    }
  const Vec3 t = ne == 0 ? Vec3::Zero() : Vec3(0.5 * (low + high));
  double rest = 0.0;
  for (std::size_t el = 0; el < ne; ++el)
    for (std::size_t d = 0; d < 3; ++d) {
      const double* c = change.data() + (el * 3 + d) * n;
      rest = std::max(rest, std::abs(c[0] - t[static_cast<Eigen::Index>(d)] / constant[el]));
      for (std::size_t i = 1; i < n; ++i) rest = std::max(rest, std::abs(c[i]));
    }
  return {t, rest};
}

const std::vector<std::uint32_t>& ContactModel::candidates(const Eigen::VectorXd& u, double t) {
  const std::size_t np = embedding_->numPoints();
  auto select = [&]() {
    const auto [translation, rest] = translationAndRest(u - clearanceU_);
    const double shift = translation.norm();
    const double swept = maxObstacleSpeed_ * std::abs(t - clearanceT_);
    candidates_.clear();
    for (std::size_t p = 0; p < np; ++p)
      if (clearance_[p] - std::abs(translationGain_[p]) * shift - rowScale_[p] * rest - swept <=
          pad_)
        candidates_.push_back(static_cast<std::uint32_t>(p));
  };
  if (clearanceU_.size() == u.size()) select();
  // Measured again when they have lost their use, unless they were of little use when fresh
  // (a body inside a surface obstacle's box).
  if (clearanceU_.size() != u.size() ||
      (4 * candidates_.size() > np && candidates_.size() > 2 * measuredCandidates_)) {
    measureClearances(u, t);
    select();
    measuredCandidates_ = candidates_.size();
  }
  return candidates_;
}

void ContactModel::displacementsAt(const std::vector<std::uint32_t>& points,
                                   const Eigen::VectorXd& u, std::vector<Vec3>& out) {
  if (knownU_.size() != u.size() || knownU_ != u) {
    knownU_ = u;
    if (++knownStamp_ == 0) {  // wrapped: forget every stamp
      std::fill(known_.begin(), known_.end(), 0);
      knownStamp_ = 1;
    }
  }
  out.resize(points.size());
  forEachPoint(points.size(), [&](std::size_t k) {
    const std::uint32_t p = points[k];
    if (known_[p] != knownStamp_) {
      knownDisplacement_[p] = embedding_->displacement(p, u);
      known_[p] = knownStamp_;
    }
    out[k] = knownDisplacement_[p];
  });
}

std::vector<Vec3> ContactModel::positionsAt(const std::vector<std::uint32_t>& points,
                                            const Eigen::VectorXd& u) {
  std::vector<Vec3> positions;
  displacementsAt(points, u, positions);
  for (std::size_t k = 0; k < points.size(); ++k) positions[k] += embedding_->points()[points[k]];
  return positions;
}

std::vector<std::uint32_t> ContactModel::activePoints() const {
  std::vector<std::uint32_t> points(active_.size());
  for (std::size_t k = 0; k < active_.size(); ++k) points[k] = active_[k].point;
  return points;
}

ContactLinearization ContactModel::linearize(const Eigen::VectorXd& u, const Eigen::VectorXd& v,
                                             double tNext, double dt) {
  const Stopwatch watch;
  const SurfaceEmbedding& e = *embedding_;
  tNext_ = tNext;
  startCoefficients_ = u;
  // Points that may touch at the predicted state u + dt v.
  const std::vector<std::uint32_t>& points = candidates(u + dt * v, tNext);
  const std::size_t nc = points.size();
  std::vector<Vec3> start, velocity(nc), predicted(nc);
  displacementsAt(points, u, start);
  forEachPoint(nc, [&](std::size_t k) {
    velocity[k] = e.displacement(points[k], v);
    predicted[k] = e.points()[points[k]] + (start[k] + dt * velocity[k]);
  });
  std::vector<ObstacleQuery> q;
  std::vector<std::uint32_t> which;
  queryAll(predicted, tNext, q, which);
  active_.clear();
  for (std::size_t k = 0; k < nc; ++k) {
    if (!(q[k].distance < 0.0) || q[k].normal.isZero()) continue;
    Active a{points[k], which[k], q[k].distance, q[k].normal, predicted[k], Vec3::Zero(), start[k]};
    const Vec3 relative = velocity[k] - obstacles_[which[k]].velocity();
    a.slip = relative - a.normal * a.normal.dot(relative);
    active_.push_back(a);
  }
  querySeconds_ += watch.seconds();
  return build();
}

bool ContactModel::adjust(const Eigen::VectorXd& uNew) {
  const Stopwatch watch;
  const SurfaceEmbedding& e = *embedding_;
  bool changed = false;
  // Drop contacts whose linearized force pulls at the new state.
  std::vector<Active> kept;
  const std::vector<Vec3> at = positionsAt(activePoints(), uNew);
  for (std::size_t k = 0; k < active_.size(); ++k) {
    const Active& a = active_[k];
    if (a.distance + a.normal.dot(at[k] - a.position) > 0.0) {
      changed = true;
      continue;
    }
    kept.push_back(a);
    isActive_[a.point] = 1;
  }
  // Add points that end inside an obstacle.
  std::vector<std::uint32_t> points;
  for (std::uint32_t p : candidates(uNew, tNext_))
    if (!isActive_[p]) points.push_back(p);
  for (const Active& a : kept) isActive_[a.point] = 0;
  const std::vector<Vec3> positions = positionsAt(points, uNew);
  std::vector<ObstacleQuery> q;
  std::vector<std::uint32_t> which;
  queryAll(positions, tNext_, q, which);
  for (std::size_t k = 0; k < points.size(); ++k) {
    if (!(q[k].distance < 0.0) || q[k].normal.isZero()) continue;
    // No slip yet: full friction. u~_n at the step's start for its force.
    kept.push_back({points[k], which[k], q[k].distance, q[k].normal, positions[k], Vec3::Zero(),
                    e.displacement(points[k], startCoefficients_)});
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
  const auto [rows, local, columns] = rowsAndColumns(e, activePoints());
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
  // Contacts with one normal (all of a half-space's) share n n^T and their tangents: their
  // K_c is (sum_k k a_k w_k w_k^T) (x) n n^T, a Gram matrix of the scalar columns, a ninth of
  // the product (the ground's 2,400 contacts in B9 took 38 ms of a 58 ms step the other way).
  const Eigen::Index ms = static_cast<Eigen::Index>(columns.size());
  std::vector<Vec3> normals;
  for (const Active& a : active_) normals.push_back(a.normal);
  const NormalGroups groups = groupByNormal(normals);
  const bool grouped = 8 * groups.normal.size() <= static_cast<std::size_t>(contacts);
  std::vector<Eigen::MatrixXd> gs, hs;  // grouped: ms x (members) scalar columns
  if (grouped)
    for (Eigen::Index size : groups.size) {
      gs.push_back(Eigen::MatrixXd::Zero(ms, size));
      if (friction) hs.push_back(Eigen::MatrixXd::Zero(ms, size));
    }
  Eigen::MatrixXd g = grouped ? Eigen::MatrixXd() : Eigen::MatrixXd::Zero(m, contacts);
  Eigen::MatrixXd h =
      friction && !grouped ? Eigen::MatrixXd::Zero(m, 2 * contacts) : Eigen::MatrixXd();
  for (Eigen::Index k = 0; k < contacts; ++k) {
    const Active& a = active_[static_cast<std::size_t>(k)];
    const double ka = options_.stiffness * areas_[a.point];
    const WeightRow& row = rows[static_cast<std::size_t>(k)];
    const Vec3 uStart = a.start;
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
      if (grouped) {
        const std::size_t gk = static_cast<std::size_t>(groups.group[static_cast<std::size_t>(k)]);
        const Eigen::Index sk2 = groups.slot[static_cast<std::size_t>(k)];
        gs[gk](base / 3, sk2) = sk * w;
        if (friction) hs[gk](base / 3, sk2) = sc * w;
      }
      for (int d = 0; d < 3; ++d) {
        if (!grouped) {
          g(base + d, k) = sk * w * a.normal[d];
          if (friction) {
            h(base + d, 2 * k) = sc * w * t1[d];
            h(base + d, 2 * k + 1) = sc * w * t2[d];
          }
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
  if (grouped) {
    Eigen::MatrixXd kc = Eigen::MatrixXd::Zero(m, m), ctm;
    if (friction) ctm = Eigen::MatrixXd::Zero(m, m);
    for (std::size_t gk = 0; gk < gs.size(); ++gk) {
      const Vec3& normal = groups.normal[gk];
      addKronecker(gs[gk] * gs[gk].transpose(), normal * normal.transpose(), kc);
      if (friction) {
        const Vec3 t1 = normal.unitOrthogonal(), t2 = normal.cross(t1);
        addKronecker(hs[gk] * hs[gk].transpose(), t1 * t1.transpose() + t2 * t2.transpose(), ctm);
      }
    }
    out.stiffness = scatter(kc);
    if (friction) out.damping = scatter(ctm);
  } else {
    const Eigen::MatrixXd kc = g * g.transpose();
    out.stiffness = scatter(kc);
    if (friction) {
      const Eigen::MatrixXd ctm = h * h.transpose();
      out.damping = scatter(ctm);
    }
  }
  return out;
}

ContactMeasure ContactModel::measure(const Eigen::VectorXd& u, double t) {
  const Stopwatch watch;
  const std::vector<std::uint32_t>& points = candidates(u, t);
  const std::vector<Vec3> positions = positionsAt(points, u);
  std::vector<ObstacleQuery> q;
  std::vector<std::uint32_t> which;
  queryAll(positions, t, q, which);
  ContactMeasure m;
  for (std::size_t k = 0; k < q.size(); ++k) {
    if (!(q[k].distance < 0.0)) continue;
    ++m.contacts;
    m.deepest = std::max(m.deepest, -q[k].distance);
    m.energy += 0.5 * options_.stiffness * areas_[points[k]] * q[k].distance * q[k].distance;
  }
  querySeconds_ += watch.seconds();
  return m;
}

}  // namespace polydg
