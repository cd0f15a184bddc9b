// Piecewise polynomials and quadrature for the Galerkin schemes (METHOD.md §9).
//
// On an interval [t_n, t_n + h], τ = (t - t_n)/h ∈ [0, 1], a curve of degree S is
//   p(τ) = p_n H00 + h v_n H10 + p_{n+1} H01 + h v_{n+1} H11 + Σ_j a_j β_j,   j = 0 .. S-4,
//   H00 = 1 - 3τ² + 2τ³, H10 = τ - 2τ² + τ³, H01 = 3τ² - 2τ³, H11 = -τ² + τ³,
//   β_j = τ²(1 - τ)²(2τ - 1)^j  (internal "bubble" coefficients, zero value and slope at both ends).
// GalerkinTable<S, Q> holds the Q Gauss–Legendre points and weights on [0, 1] and every basis
// function's value and first three τ-derivatives there.
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>

namespace lpshoot {

// Gauss–Legendre points c_i and weights b_i on [0, 1] (Q = 1 .. 5), exact for degree 2Q - 1.
inline void gauss_legendre(int Q, double* c, double* b) {
  // Points and weights on [-1, 1] (abscissas ascending).
  static const double x1[] = {0.0}, w1[] = {2.0};
  static const double x2[] = {-0.57735026918962576451, 0.57735026918962576451}, w2[] = {1.0, 1.0};
  static const double x3[] = {-0.77459666924148337704, 0.0, 0.77459666924148337704},
                      w3[] = {0.55555555555555555556, 0.88888888888888888889, 0.55555555555555555556};
  static const double x4[] = {-0.86113631159405257522, -0.33998104358485626480, 0.33998104358485626480,
                              0.86113631159405257522},
                      w4[] = {0.34785484513745385737, 0.65214515486254614263, 0.65214515486254614263,
                              0.34785484513745385737};
  static const double x5[] = {-0.90617984593866399280, -0.53846931010568309104, 0.0, 0.53846931010568309104,
                              0.90617984593866399280},
                      w5[] = {0.23692688505618908751, 0.47862867049936646804, 0.56888888888888888889,
                              0.47862867049936646804, 0.23692688505618908751};
  const double* xs[] = {x1, x2, x3, x4, x5};
  const double* ws[] = {w1, w2, w3, w4, w5};
  if (Q < 1 || Q > 5) throw std::invalid_argument("gauss_legendre: 1 to 5 points");
  for (int i = 0; i < Q; ++i) {
    c[i] = 0.5 * (1.0 + xs[Q - 1][i]);
    b[i] = 0.5 * ws[Q - 1][i];
  }
}

// Monomial coefficients (degree <= 7) of basis function f: 0..3 the cubic Hermite functions,
// 4 + j the bubble β_j.
inline std::array<double, 8> hermite_basis_coefficients(int f) {
  std::array<double, 8> c{};
  switch (f) {
    case 0: c[0] = 1, c[2] = -3, c[3] = 2; return c;  // H00
    case 1: c[1] = 1, c[2] = -2, c[3] = 1; return c;  // H10
    case 2: c[2] = 3, c[3] = -2; return c;            // H01
    case 3: c[2] = -1, c[3] = 1; return c;            // H11
    default: break;
  }
  // β_j = (τ² - 2τ³ + τ⁴)(2τ - 1)^j
  c[2] = 1, c[3] = -2, c[4] = 1;
  for (int j = 0; j < f - 4; ++j) {
    std::array<double, 8> next{};
    for (int k = 0; k < 7; ++k) {
      next[k + 1] += 2 * c[k];
      next[k] -= c[k];
    }
    c = next;
  }
  return c;
}

// The k-th τ-derivative (k = 0..3) of basis function f at τ.
inline double hermite_basis(int f, int k, double tau) {
  std::array<double, 8> c = hermite_basis_coefficients(f);
  for (int i = 0; i < k; ++i) {
    for (int p = 0; p < 7; ++p) c[p] = (p + 1) * c[p + 1];
    c[7] = 0;
  }
  double v = 0;
  for (int p = 7; p >= 0; --p) v = v * tau + c[p];
  return v;
}

template <int S, int Q>
struct GalerkinTable {
  static_assert(S >= 3 && S <= 6, "Galerkin curves of degree 3 to 6");
  static_assert(Q >= 1 && Q <= 5, "1 to 5 Gauss points");
  static constexpr int functions = S + 1;  // 4 Hermite + S - 3 bubbles
  std::array<double, Q> c{}, b{};
  // basis[i][f][k]: k-th τ-derivative of function f at Gauss point i.
  std::array<std::array<std::array<double, 4>, functions>, Q> basis{};

  static const GalerkinTable& get() {
    static const GalerkinTable t = [] {
      GalerkinTable g;
      gauss_legendre(Q, g.c.data(), g.b.data());
      for (int i = 0; i < Q; ++i)
        for (int f = 0; f < functions; ++f)
          for (int k = 0; k < 4; ++k) g.basis[i][f][k] = hermite_basis(f, k, g.c[i]);
      return g;
    }();
    return t;
  }
};

}  // namespace lpshoot
