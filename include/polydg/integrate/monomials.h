// The monomial basis x^a y^b z^c used for every moment array in polydg, and its ordering.
//
// Ordering (graded, then by descending power of x, then of y):
//   degree 0: 1
//   degree 1: x, y, z
//   degree 2: x^2, xy, xz, y^2, yz, z^2
//   degree 3: x^3, x^2y, x^2z, xy^2, xyz, xz^2, y^3, y^2z, yz^2, z^3
//   ...
// so the moments up to degree K are a prefix of the moments up to any higher degree.
#pragma once

#include <array>
#include <cassert>

namespace polydg {

/// Highest total degree for which moment kernels are instantiated.
inline constexpr int kMaxMomentDegree = 8;

/// Number of monomials of total degree <= degree in three variables: (d+1)(d+2)(d+3)/6.
constexpr int numMonomials(int degree) {
  return degree < 0 ? 0 : (degree + 1) * (degree + 2) * (degree + 3) / 6;
}

/// Position of x^a y^b z^c in the ordering above.
constexpr int monomialIndex(int a, int b, int c) {
  const int d = a + b + c;
  return numMonomials(d - 1) + (d - a) * (d - a + 1) / 2 + c;
}

struct Exponents {
  int a = 0, b = 0, c = 0;
  constexpr int degree() const { return a + b + c; }
};

/// Table of exponents for every monomial up to kMaxMomentDegree, in order.
inline constexpr auto kMonomialTable = [] {
  std::array<Exponents, numMonomials(kMaxMomentDegree)> table{};
  int i = 0;
  for (int d = 0; d <= kMaxMomentDegree; ++d)
    for (int a = d; a >= 0; --a)
      for (int b = d - a; b >= 0; --b) table[i++] = Exponents{a, b, d - a - b};
  return table;
}();

constexpr Exponents monomialExponents(int index) {
  assert(index >= 0 && index < numMonomials(kMaxMomentDegree));
  return kMonomialTable[index];
}

/// Binomial coefficients C(n, k) for n, k <= N, as doubles.
template <int N>
inline constexpr auto kBinomial = [] {
  std::array<std::array<double, N + 1>, N + 1> c{};
  for (int n = 0; n <= N; ++n) {
    c[n][0] = 1.0;
    for (int k = 1; k <= n; ++k) c[n][k] = c[n - 1][k - 1] + (k <= n - 1 ? c[n - 1][k] : 0.0);
  }
  return c;
}();

static_assert(monomialIndex(0, 0, 0) == 0);
static_assert(monomialIndex(0, 0, 1) == 3);
static_assert(monomialIndex(1, 1, 0) == 5);
static_assert(monomialIndex(0, 0, 2) == 9);
static_assert(monomialIndex(2, 0, 1) == 12);

}  // namespace polydg
