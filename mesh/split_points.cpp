#include "mesh/split_points.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <CGAL/FPU.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "util/resident.h"

namespace polydg {

namespace {

using Exact = SplitPoints::Exact;
using ExactPoint = SplitPoints::ExactPoint;

/// True if a rounded difference `distance` is certainly larger in magnitude than `radius`, the
/// bound on the error of its operands: the factors cover the rounding of the difference and of
/// the sum of radii (each within 2^-53 relative).
bool beyond(double distance, double radius) {
  return std::abs(distance) * (1.0 - 1e-15) > radius * (1.0 + 1e-15);
}

int signOf(const Exact& x) { return x < 0 ? -1 : (x > 0 ? 1 : 0); }

/// -1, 0, +1 if the interval's sign is certain, else 2.
template <class I>
int certainSign(const I& x) {
  if (x.inf() > 0) return 1;
  if (x.sup() < 0) return -1;
  if (x.inf() == 0 && x.sup() == 0) return 0;
  return 2;
}

constexpr int kUnknown = 2;

/// Where segment P Q meets `plane`, exactly (P and Q on opposite exact sides of it).
ExactPoint crossing(const Plane& plane, const ExactPoint& p, const ExactPoint& q) {
  Exact np(0), nq(0);
  for (int i = 0; i < 3; ++i) {
    np += Exact(plane.normal[i]) * p[i];
    nq += Exact(plane.normal[i]) * q[i];
  }
  const Exact t = (Exact(plane.offset) - np) / (nq - np);
  ExactPoint x;
  for (int i = 0; i < 3; ++i) x[i] = p[i] + t * (q[i] - p[i]);
  if (plane.axis >= 0) x[plane.axis] = Exact(plane.offset);
  return x;
}

/// The radius as a float no smaller than it.
float roundedUp(double radius) {
  if (!(radius < double(std::numeric_limits<float>::max())))
    return std::numeric_limits<float>::infinity();
  float r = static_cast<float>(radius);
  if (double(r) < radius) r = std::nextafter(r, std::numeric_limits<float>::infinity());
  return r;
}

}  // namespace

Projection Projection::dropping(int axis, int sign) {
  Projection p;
  p.drop = axis;
  p.u = (axis + 1) % 3;
  p.w = (axis + 2) % 3;
  p.sign = sign;
  return p;
}

SplitPoints::SplitPoints(const std::vector<Vec3>& points,
                         const std::vector<std::uint32_t>& onPlane) {
  if (!onPlane.empty() && onPlane.size() != points.size())
    throw std::invalid_argument("SplitPoints: one plane id per point");
  records_.reserve(2 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    Record r;
    r.position = points[i];
    r.onPlane = onPlane.empty() ? kNoPlane : onPlane[i];
    records_.push_back(r);
  }
}

std::vector<Vec3> SplitPoints::positions(std::size_t room) const {
  const std::size_t n = records_.size();
  std::vector<Vec3> out = residentVector<Vec3>(n + room);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        out[i] = records_[i].position;
                    });
  return out;
}

void SplitPoints::rememberPlane(const Plane& plane, std::uint32_t id) {
  decltype(planes_)::const_accessor known;
  if (!planes_.find(known, id)) planes_.insert({id, plane});
}

Plane SplitPoints::planeOf(std::uint32_t id) const {
  decltype(planes_)::const_accessor found;
  if (!planes_.find(found, id)) throw std::logic_error("SplitPoints: unknown plane");
  return found->second;
}

SplitPoints::Box SplitPoints::box(std::uint32_t v) const {
  const Record& r = records_[v];
  Box b;
  for (int i = 0; i < 3; ++i) {
    b[i] = Interval(r.position[i]);
    if (r.radius[i] != 0.0f) b[i] += Interval(-double(r.radius[i]), double(r.radius[i]));
  }
  return b;
}

ExactPoint SplitPoints::exact(std::uint32_t v) const {
  {
    decltype(exact_)::const_accessor known;
    if (exact_.find(known, v)) return known->second;
  }
  const Record& r = records_[v];
  ExactPoint x;
  if (r.a == r.b) {
    for (int i = 0; i < 3; ++i) x[i] = Exact(r.position[i]);
  } else {
    x = crossing(planeOf(r.onPlane), exact(r.a), exact(r.b));
  }
  exact_.insert({v, x});
  return x;
}

std::uint32_t SplitPoints::addCrossing(std::uint32_t u, std::uint32_t v, const Plane& plane,
                                       std::uint32_t id) {
  const Vec3& pu = records_[u].position;
  const Vec3& pv = records_[v].position;
  const bool uFirst =
      std::lexicographical_compare(pu.data(), pu.data() + 3, pv.data(), pv.data() + 3) ||
      (pu == pv && u < v);
  const std::uint32_t a = uFirst ? u : v, b = uFirst ? v : u;
  const Vec3 p = records_[a].position, q = records_[b].position;
  Vec3 r;
  if (plane.axis >= 0) {
    const int k = plane.axis;
    r = p + ((plane.offset - p[k]) / (q[k] - p[k])) * (q - p);
  } else {
    const double dp = plane.normal.dot(p) - plane.offset;
    const double dq = plane.normal.dot(q) - plane.offset;
    r = p + (dp / (dp - dq)) * (q - p);
  }
  if (!r.allFinite()) {
    // Both ends' rounded positions are on the plane, or at equal rounded distances from it,
    // though they are exactly on opposite sides: the interpolation divides by zero. The exact
    // crossing, rounded, instead.
    const ExactPoint x = crossing(plane, exact(a), exact(b));
    for (int i = 0; i < 3; ++i) r[i] = CGAL::to_double(x[i]);
  }
  // Inside the edge's box, so later comparisons of the position keep the order of the edge's
  // ends, and exactly on an axis-aligned plane.
  for (int i = 0; i < 3; ++i) r[i] = std::clamp(r[i], std::min(p[i], q[i]), std::max(p[i], q[i]));
  if (plane.axis >= 0) r[plane.axis] = plane.offset;
  Record record;
  record.onPlane = id;
  record.a = a;
  record.b = b;
  {
    // The exact crossing lies in the crossing of the ends' boxes and in the hull of those boxes;
    // the radii bound its distance from the position.
    CGAL::Protect_FPU_rounding<true> upward;
    const Box P = box(a), Q = box(b);
    Interval t;
    bool finite = false;
    if (plane.axis >= 0) {
      const Interval d = Q[plane.axis] - P[plane.axis];
      if (certainSign(d) != 0 && certainSign(d) != kUnknown) {
        t = (Interval(plane.offset) - P[plane.axis]) / d;
        finite = true;
      }
    } else {
      Interval dp(-plane.offset), dq(-plane.offset);
      for (int i = 0; i < 3; ++i) {
        dp += Interval(plane.normal[i]) * P[i];
        dq += Interval(plane.normal[i]) * Q[i];
      }
      const Interval d = dp - dq;
      if (certainSign(d) != 0 && certainSign(d) != kUnknown) {
        t = dp / d;
        finite = true;
      }
    }
    for (int i = 0; i < 3; ++i) {
      double lo = std::min(P[i].inf(), Q[i].inf()), hi = std::max(P[i].sup(), Q[i].sup());
      if (finite) {
        const Interval xi = P[i] + t * (Q[i] - P[i]);
        lo = std::max(lo, xi.inf());
        hi = std::min(hi, xi.sup());
      }
      if (i == plane.axis) lo = hi = plane.offset;
      record.radius[i] = roundedUp(std::max(hi - r[i], r[i] - lo));  // rounded up
    }
  }
  record.position = Vec3(r.x() + 0.0, r.y() + 0.0, r.z() + 0.0);
  return static_cast<std::uint32_t>(records_.push_back(record) - records_.begin());
}

int SplitPoints::side(std::uint32_t v, const Plane& plane, std::uint32_t id) const {
  const Record& r = records_[v];
  if (r.onPlane == id) return 0;
  if (plane.axis >= 0) {
    const int k = plane.axis;
    const double x = r.position[k];
    if (r.radius[k] == 0.0f || beyond(x - plane.offset, r.radius[k]))
      return x < plane.offset ? -1 : (x > plane.offset ? 1 : 0);
    return signOf(exact(v)[k] - Exact(plane.offset));
  }
  if (r.radius[0] == 0.0f && r.radius[1] == 0.0f && r.radius[2] == 0.0f)
    return plane.side(r.position);
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const Box b = box(v);
    Interval s(-plane.offset);
    for (int i = 0; i < 3; ++i) s += Interval(plane.normal[i]) * b[i];
    if (const int sign = certainSign(s); sign != kUnknown) return sign;
  }
  const ExactPoint x = exact(v);
  Exact s = -Exact(plane.offset);
  for (int i = 0; i < 3; ++i) s += Exact(plane.normal[i]) * x[i];
  return signOf(s);
}

int SplitPoints::compare(std::uint32_t v, std::uint32_t w, int k) const {
  if (v == w) return 0;
  const Record& a = records_[v];
  const Record& b = records_[w];
  const double x = a.position[k], y = b.position[k];
  if ((a.radius[k] == 0.0f && b.radius[k] == 0.0f) ||
      beyond(x - y, double(a.radius[k]) + double(b.radius[k])))
    return x < y ? -1 : (x > y ? 1 : 0);
  const Exact d = exact(v)[k] - exact(w)[k];
  return signOf(d);
}

int SplitPoints::compareLexicographically(std::uint32_t v, std::uint32_t w) const {
  for (int k = 0; k < 3; ++k)
    if (const int c = compare(v, w, k); c != 0) return c;
  return 0;
}

int SplitPoints::orientation(std::uint32_t a, std::uint32_t b, std::uint32_t c,
                             const Projection& p) const {
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const Box A = box(a), B = box(b), C = box(c);
    const Interval det =
        (B[p.u] - A[p.u]) * (C[p.w] - A[p.w]) - (B[p.w] - A[p.w]) * (C[p.u] - A[p.u]);
    if (const int s = certainSign(det); s != kUnknown) return s * p.sign;
  }
  const ExactPoint A = exact(a), B = exact(b), C = exact(c);
  const Exact det = (B[p.u] - A[p.u]) * (C[p.w] - A[p.w]) - (B[p.w] - A[p.w]) * (C[p.u] - A[p.u]);
  return signOf(det) * p.sign;
}

int SplitPoints::dotSign(std::uint32_t o, std::uint32_t a, std::uint32_t b,
                         const Projection& p) const {
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const Box O = box(o), A = box(a), B = box(b);
    const Interval dot =
        (A[p.u] - O[p.u]) * (B[p.u] - O[p.u]) + (A[p.w] - O[p.w]) * (B[p.w] - O[p.w]);
    if (const int s = certainSign(dot); s != kUnknown) return s;
  }
  const ExactPoint O = exact(o), A = exact(a), B = exact(b);
  return signOf((A[p.u] - O[p.u]) * (B[p.u] - O[p.u]) + (A[p.w] - O[p.w]) * (B[p.w] - O[p.w]));
}

namespace {

/// Twice the signed area of a loop projected by p (without p's sign), about its first point.
template <class Number, class PointOf>
Number twiceArea(std::span<const std::uint32_t> loop, const Projection& p, const PointOf& point) {
  Number sum(0);
  if (loop.size() < 3) return sum;
  const auto c = point(loop[0]);
  for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
    const auto x = point(loop[i]), y = point(loop[i + 1]);
    sum += (x[p.u] - c[p.u]) * (y[p.w] - c[p.w]) - (x[p.w] - c[p.w]) * (y[p.u] - c[p.u]);
  }
  return sum;
}

}  // namespace

int SplitPoints::areaSign(std::span<const std::uint32_t> loop, const Projection& p) const {
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const Interval a = twiceArea<Interval>(loop, p, [this](std::uint32_t v) { return box(v); });
    if (const int s = certainSign(a); s != kUnknown) return s * p.sign;
  }
  const Exact a = twiceArea<Exact>(loop, p, [this](std::uint32_t v) { return exact(v); });
  return signOf(a) * p.sign;
}

int SplitPoints::compareAreas(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b,
                              const Projection& p) const {
  {
    CGAL::Protect_FPU_rounding<true> upward;
    auto boxOf = [this](std::uint32_t v) { return box(v); };
    const Interval x = CGAL::abs(twiceArea<Interval>(a, p, boxOf));
    const Interval y = CGAL::abs(twiceArea<Interval>(b, p, boxOf));
    if (x.sup() < y.inf()) return -1;
    if (y.sup() < x.inf()) return 1;
  }
  auto exactOf = [this](std::uint32_t v) { return exact(v); };
  const Exact x = CGAL::abs(twiceArea<Exact>(a, p, exactOf));
  const Exact y = CGAL::abs(twiceArea<Exact>(b, p, exactOf));
  return x < y ? -1 : (y < x ? 1 : 0);
}

namespace {

/// A polygon's area vector (twice it: the sum over its loops of the cross products about its
/// first point) in the number type of `point`.
template <class Number, class PointOf>
std::array<Number, 3> areaVector(const PolygonLoops& polygon, const PointOf& point) {
  std::array<Number, 3> n{Number(0), Number(0), Number(0)};
  const auto c = point(polygon.vertices[0]);
  std::size_t begin = 0;
  for (const std::uint32_t end : polygon.loopEnd) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto x = point(polygon.vertices[i]);
      const auto y = point(polygon.vertices[i + 1 == end ? begin : i + 1]);
      for (int k = 0; k < 3; ++k) {
        const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        n[k] += (x[k1] - c[k1]) * (y[k2] - c[k2]) - (x[k2] - c[k2]) * (y[k1] - c[k1]);
      }
    }
    begin = end;
  }
  return n;
}

}  // namespace

std::array<SplitPoints::Interval, 3> SplitPoints::intervalNormal(
    const PolygonLoops& polygon) const {
  return areaVector<Interval>(polygon, [this](std::uint32_t v) { return box(v); });
}

ExactPoint SplitPoints::exactNormal(const PolygonLoops& polygon) const {
  return areaVector<Exact>(polygon, [this](std::uint32_t v) { return exact(v); });
}

int SplitPoints::normalDotSign(const PolygonLoops& polygon, const Vec3& normal) const {
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const auto n = intervalNormal(polygon);
    Interval dot(0);
    for (int i = 0; i < 3; ++i) dot += n[i] * Interval(normal[i]);
    if (const int s = certainSign(dot); s != kUnknown) return s;
  }
  const ExactPoint n = exactNormal(polygon);
  Exact dot(0);
  for (int i = 0; i < 3; ++i) dot += n[i] * Exact(normal[i]);
  return signOf(dot);
}

int SplitPoints::normalCrossSign(const PolygonLoops& polygon, const Vec3& normal, int j) const {
  const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const auto n = intervalNormal(polygon);
    const Interval c = n[j1] * Interval(normal[j2]) - n[j2] * Interval(normal[j1]);
    if (const int s = certainSign(c); s != kUnknown) return s;
  }
  const ExactPoint n = exactNormal(polygon);
  return signOf(n[j1] * Exact(normal[j2]) - n[j2] * Exact(normal[j1]));
}

Projection SplitPoints::projectionOf(const PolygonLoops& polygon) const {
  {
    CGAL::Protect_FPU_rounding<true> upward;
    const auto n = intervalNormal(polygon);
    int m = 0;
    for (int k = 1; k < 3; ++k)
      if (CGAL::abs(n[k]).sup() > CGAL::abs(n[m]).sup()) m = k;
    if (const int s = certainSign(n[m]); s != kUnknown && s != 0) return Projection::dropping(m, s);
  }
  const ExactPoint n = exactNormal(polygon);
  int m = 0;
  for (int k = 1; k < 3; ++k)
    if (CGAL::abs(n[k]) > CGAL::abs(n[m])) m = k;
  if (n[m] == 0) throw std::logic_error("plane split: a polygon of zero area");
  return Projection::dropping(m, signOf(n[m]));
}

Projection SplitPoints::projectionOf(const Vec3& normal) {
  int m = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(normal[k]) > std::abs(normal[m])) m = k;
  return Projection::dropping(m, normal[m] > 0 ? 1 : -1);
}

}  // namespace polydg
