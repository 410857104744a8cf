// Compile-time tables over the monomials of integrate/monomials.h used by the DG kernels:
// products of monomials (a + b), derivatives (a - e_k) and binomial coefficients. Internal to
// physics/.
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "polydg/integrate/monomials.h"

namespace polydg::detail {

/// Highest polynomial degree of the DG bases for which kernels are instantiated.
inline constexpr int kMaxBasisDegree = 3;

/// Calls f(std::integral_constant<int, P>{}) for a runtime basis degree 1..kMaxBasisDegree.
template <class F>
decltype(auto) dispatchBasisDegree(int degree, F&& f);

template <int P>
struct PolyTables {
  static constexpr int N = numMonomials(P);       ///< functions per component
  static constexpr int N1 = numMonomials(P - 1);  ///< monomials of degree <= P - 1
  static constexpr int N2 = numMonomials(2 * P);  ///< moments needed for products

  /// sum[a][b]: index of the monomial x^(alpha_a + alpha_b).
  static constexpr auto sum = [] {
    std::array<std::array<int, N>, N> s{};
    for (int a = 0; a < N; ++a)
      for (int b = 0; b < N; ++b) {
        const Exponents ea = kMonomialTable[a], eb = kMonomialTable[b];
        s[a][b] = monomialIndex(ea.a + eb.a, ea.b + eb.b, ea.c + eb.c);
      }
    return s;
  }();

  /// pred[k][a]: index of alpha_a - e_k, or -1 if alpha_a has no factor of variable k.
  static constexpr auto pred = [] {
    std::array<std::array<int, N>, 3> p{};
    for (int a = 0; a < N; ++a) {
      const Exponents e = kMonomialTable[a];
      p[0][a] = e.a > 0 ? monomialIndex(e.a - 1, e.b, e.c) : -1;
      p[1][a] = e.b > 0 ? monomialIndex(e.a, e.b - 1, e.c) : -1;
      p[2][a] = e.c > 0 ? monomialIndex(e.a, e.b, e.c - 1) : -1;
    }
    return p;
  }();

  /// power[k][a]: the exponent of variable k in monomial a.
  static constexpr auto power = [] {
    std::array<std::array<int, N>, 3> p{};
    for (int a = 0; a < N; ++a) {
      const Exponents e = kMonomialTable[a];
      p[0][a] = e.a;
      p[1][a] = e.b;
      p[2][a] = e.c;
    }
    return p;
  }();

  /// Binomial coefficients C(n, k) for n, k <= P.
  static constexpr auto binomial = kBinomial<P>;
};

template <class F>
decltype(auto) dispatchBasisDegree(int degree, F&& f) {
  switch (degree) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    default:
      throw std::invalid_argument("basis degree " + std::to_string(degree) + " is outside 1.." +
                                  std::to_string(kMaxBasisDegree));
  }
}
static_assert(kMaxBasisDegree == 3, "dispatchBasisDegree lists every degree up to the maximum");

}  // namespace polydg::detail
