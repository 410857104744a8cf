#include "polydg/integrate/moments.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace polydg {

namespace {

constexpr double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

/// Per-degree constant tables, computed at compile time.
template <int K>
struct Tables {
  static constexpr int N = numMonomials(K);
  /// alpha! / (|alpha| + 2)!: the triangle (2-simplex) moment factor.
  static constexpr auto faceCoef = [] {
    std::array<double, N> c{};
    for (int i = 0; i < N; ++i) {
      const Exponents e = kMonomialTable[i];
      c[i] = factorial(e.a) * factorial(e.b) * factorial(e.c) / factorial(e.degree() + 2);
    }
    return c;
  }();
  /// 1 / (|alpha| + 3): Euler's identity factor from faces to the volume.
  static constexpr auto volumeCoef = [] {
    std::array<double, N> c{};
    for (int i = 0; i < N; ++i) c[i] = 1.0 / (kMonomialTable[i].degree() + 3);
    return c;
  }();
  static constexpr auto binomial = kBinomial<K>;
};

/// Calls f(std::integral_constant<int, K>) for the runtime degree.
template <class F>
decltype(auto) dispatchDegree(int degree, F&& f) {
  switch (degree) {
    case 0: return f(std::integral_constant<int, 0>{});
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 5: return f(std::integral_constant<int, 5>{});
    case 6: return f(std::integral_constant<int, 6>{});
    case 7: return f(std::integral_constant<int, 7>{});
    case 8: return f(std::integral_constant<int, 8>{});
    default:
      throw std::invalid_argument("moment degree " + std::to_string(degree) + " is outside 0.." +
                                  std::to_string(kMaxMomentDegree));
  }
}
static_assert(kMaxMomentDegree == 8, "dispatchDegree lists every degree up to the maximum");

/// Index of alpha - e_axis for each monomial alpha, or N (a slot holding zero) if alpha has no
/// factor of that variable.
template <int K>
inline constexpr auto kPredecessor = [] {
  constexpr int N = numMonomials(K);
  std::array<std::array<int, N>, 3> p{};
  for (int j = 0; j < N; ++j) {
    const Exponents e = kMonomialTable[j];
    p[0][j] = e.a > 0 ? monomialIndex(e.a - 1, e.b, e.c) : N;
    p[1][j] = e.b > 0 ? monomialIndex(e.a, e.b - 1, e.c) : N;
    p[2][j] = e.c > 0 ? monomialIndex(e.a, e.b, e.c - 1) : N;
  }
  return p;
}();

/// Coefficients H[alpha] of c^alpha in h_k(a.c, b.c) = sum_{i+j=k} (a.c)^i (b.c)^j, for every
/// alpha with |alpha| = k <= K, by H_k = (a.c)^k + (b.c) H_{k-1}: both are products with a
/// linear form, so each coefficient takes three multiply-adds per factor. With these,
///   int_{triangle(0, a, b)} x^alpha dA = 2 A alpha! / (|alpha| + 2)! H[alpha].
/// Arrays have N + 1 entries; entry N stays zero.
template <int K>
inline void simplexCoefficients(const Vec3& a, const Vec3& b, double* A, double* H) {
  constexpr int N = numMonomials(K);
  const auto& p = kPredecessor<K>;
  A[N] = H[N] = 0.0;
  A[0] = H[0] = 1.0;
#pragma GCC unroll 256
  for (int j = 1; j < N; ++j) {
    A[j] = a.x() * A[p[0][j]] + a.y() * A[p[1][j]] + a.z() * A[p[2][j]];
    H[j] = A[j] + b.x() * H[p[0][j]] + b.y() * H[p[1][j]] + b.z() * H[p[2][j]];
  }
}

template <int K>
void faceMomentsK(const PolyMesh& mesh, FaceId f, double* out, Vec3& normal) {
  using T = Tables<K>;
  const Face& face = mesh.face(f);
  const Vec3 c = mesh.position(face.vertices.front());

  const Vec3 twiceArea = 2.0 * areaVector(mesh, f);  // about c, the face's first vertex
  std::fill(out, out + T::N, 0.0);
  const double norm = twiceArea.norm();
  if (norm == 0.0) {
    normal = Vec3::Zero();
    return;
  }
  normal = twiceArea / norm;

  double A[T::N + 1], H[T::N + 1];
  for (std::size_t k = 0; k < face.numLoops(); ++k) {
    const auto loop = face.loop(k);
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 a = mesh.position(loop[i]) - c;
      const Vec3 b = mesh.position(loop[(i + 1) % n]) - c;
      const double w = a.cross(b).dot(normal);  // twice the signed triangle area
      if (w == 0.0) continue;
      simplexCoefficients<K>(a, b, A, H);
#pragma GCC unroll 256
      for (int j = 0; j < T::N; ++j) out[j] += w * H[j];
    }
  }
  for (int j = 0; j < T::N; ++j) out[j] *= T::faceCoef[j];
}

/// The terms of a one-dimensional binomial shift along one axis, flattened at compile time:
///   out[j] = sum over terms t with target j of coef[t] * p[power[t]] * in[source[t]],
/// where p[] are the powers of the offset along that axis. Terms are grouped by target.
template <int K, int Axis>
struct ShiftTerms {
  static constexpr int N = numMonomials(K);
  static constexpr int count = [] {
    int c = 0;
    for (int j = 0; j < N; ++j) {
      const Exponents e = kMonomialTable[j];
      c += (Axis == 0 ? e.a : Axis == 1 ? e.b : e.c) + 1;
    }
    return c;
  }();
  struct Term {
    int target, source, power;
    double coef;
  };
  static constexpr auto terms = [] {
    std::array<Term, count> t{};
    int c = 0;
    for (int j = 0; j < N; ++j) {
      const Exponents e = kMonomialTable[j];
      const int m = Axis == 0 ? e.a : Axis == 1 ? e.b : e.c;
      for (int i = 0; i <= m; ++i) {
        const int src = Axis == 0   ? monomialIndex(i, e.b, e.c)
                        : Axis == 1 ? monomialIndex(e.a, i, e.c)
                                    : monomialIndex(e.a, e.b, i);
        t[c++] = Term{j, src, m - i, Tables<K>::binomial[m][i]};
      }
    }
    return t;
  }();
};

template <int K, int Axis>
inline void shiftAxis(const double* p, const double* in, double* out) {
  using S = ShiftTerms<K, Axis>;
  for (int j = 0; j < S::N; ++j) out[j] = 0.0;
#pragma GCC unroll 256
  for (int t = 0; t < S::count; ++t) {
    const auto& term = S::terms[t];
    out[term.target] += term.coef * p[term.power] * in[term.source];
  }
}

template <int K>
void shiftK(const Vec3& d, const double* in, double* out) {
  double px[K + 1], py[K + 1], pz[K + 1];
  px[0] = py[0] = pz[0] = 1.0;
  for (int m = 1; m <= K; ++m) {
    px[m] = px[m - 1] * d.x();
    py[m] = py[m - 1] * d.y();
    pz[m] = pz[m - 1] * d.z();
  }
  double tmp[Tables<K>::N];
  shiftAxis<K, 0>(px, in, out);
  shiftAxis<K, 1>(py, out, tmp);
  shiftAxis<K, 2>(pz, tmp, out);
}

template <int K>
void accumulateK(const double* faceMom, const Vec3& faceRef, const Vec3& normal, bool reversed,
                 const Vec3& origin, double* scratch, double* out) {
  using T = Tables<K>;
  const Vec3 d = faceRef - origin;
  double h = normal.dot(d);
  if (h == 0.0) return;  // the face's plane passes through the origin: its cone is flat
  if (reversed) h = -h;
  shiftK<K>(d, faceMom, scratch);
  for (int j = 0; j < T::N; ++j) out[j] += h * T::volumeCoef[j] * scratch[j];
}

void requireSize(std::span<const double> s, int degree, const char* what) {
  if (s.size() < static_cast<std::size_t>(numMonomials(degree)))
    throw std::invalid_argument(std::string(what) + ": buffer smaller than numMonomials(degree)");
}

}  // namespace

void faceMoments(const PolyMesh& mesh, FaceId f, int degree, std::span<double> out, Vec3& normal) {
  requireSize(out, degree, "faceMoments");
  dispatchDegree(degree, [&](auto k) { faceMomentsK<k()>(mesh, f, out.data(), normal); });
}

void shiftMoments(int degree, const Vec3& d, std::span<const double> in, std::span<double> out) {
  requireSize(in, degree, "shiftMoments");
  requireSize(out, degree, "shiftMoments");
  dispatchDegree(degree, [&](auto k) { shiftK<k()>(d, in.data(), out.data()); });
}

void accumulateElementMoments(int degree, std::span<const double> faceMom, const Vec3& faceRef,
                              const Vec3& normal, bool reversed, const Vec3& origin,
                              std::span<double> scratch, std::span<double> out) {
  requireSize(faceMom, degree, "accumulateElementMoments");
  requireSize(scratch, degree, "accumulateElementMoments");
  requireSize(out, degree, "accumulateElementMoments");
  dispatchDegree(degree, [&](auto k) {
    accumulateK<k()>(faceMom.data(), faceRef, normal, reversed, origin, scratch.data(), out.data());
  });
}

std::vector<double> elementMoments(const PolyMesh& mesh, ElementId e, int degree,
                                   const Vec3& origin) {
  const std::size_t n = static_cast<std::size_t>(numMonomials(degree));
  std::vector<double> out(n, 0.0), face(n), scratch(n);
  for (const FaceUse& use : mesh.element(e).faces) {
    Vec3 normal;
    faceMoments(mesh, use.face, degree, face, normal);
    accumulateElementMoments(degree, face, faceReferencePoint(mesh, use.face), normal, use.reversed,
                             origin, scratch, out);
  }
  return out;
}

std::vector<double> elementMoments(const PolyMesh& mesh, ElementId e, int degree) {
  return elementMoments(mesh, e, degree, elementReferencePoint(mesh, e));
}

std::vector<double> normalizedMoments(std::span<const double> moments, int degree, double length) {
  const int n = numMonomials(degree);
  std::vector<double> out(static_cast<std::size_t>(n));
  const double volume = moments[0];
  for (int j = 0; j < n; ++j)
    out[j] = moments[j] / (volume * std::pow(length, kMonomialTable[j].degree()));
  return out;
}

}  // namespace polydg
