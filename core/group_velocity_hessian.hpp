// The body velocity jet Ω, Ω' of exp(ξ(s)) with its gradient and Hessian in the jet inputs
// ξ, ξ', ξ'' (issue 9), written directly into Hess<N> at the inputs' variable indices.
//
// galerkin_group_interval.hpp's seeded_jet needs Ω and Ω' as Hess functions of the 3d inputs.
// Running group_velocity.hpp's closed form in Hess<3d> arithmetic carried every intermediate's
// full Hessian through ~20 products (beanie, Galerkin 6: ~14% of a step with sensitivities).
// But each output is a short sum of terms C(w) s x (group_velocity.hpp, SE(2), complex notation,
// J ≅ i):
//   Ω_v  = A v1 + w1 B v,
//   Ω'_v = A v2 + w1 P v1 + w2 B v + w1² B' v,      P = A' + B,
// with C a complex function of the angle w alone, s ∈ {1, w1, w2, w1²} and x ∈ {v, v1, v2}
// complex and linear, each variable in at most one factor. So each term's derivatives are
// products of C, C', C'' with s, ∂s and x, and ∂²/∂x² = 0:
//   ∂_w T = C' s x,  ∂_x T = C s (·1 or ·i),  ∂_j T = C s_j x,
//   ∂²_ww T = C'' s x,  ∂²_wx T = C' s,  ∂²_wj T = C' s_j x,  ∂²_xj T = C s_j,  ∂²_jk T = C s_jk x.
// The angle functions' derivatives to third order come from one Poly<3> evaluation.
// R^n and SO(2): Ω = ξ', Ω' = ξ'' (seeded variables). Products: by factor.
// tests/test_scalar_tower.cpp checks each group against the closed form run in Hess arithmetic.
#pragma once

#include "group_velocity.hpp"
#include "hessian_scalar.hpp"

#include <complex>

namespace lpshoot {

template <class G>
struct SeededVelocity {
  static constexpr bool available = false;
};

template <int n>
struct SeededVelocity<Rn<n>> {
  static constexpr bool available = true;
  // idx(k, a): the variable index of ξ^(k)(a). Om and dOm point to G::dim zero Hess<N>.
  template <int N, class Index>
  static void jet(const double*, const double* x1, const double* x2, const Index& idx, Hess<N>* Om, Hess<N>* dOm) {
    for (int a = 0; a < n; ++a) {
      make_variable_in_place(Om[a], x1[a], idx(1, a));
      make_variable_in_place(dOm[a], x2[a], idx(2, a));
    }
  }
};

template <>
struct SeededVelocity<SO2> {
  static constexpr bool available = true;
  template <int N, class Index>
  static void jet(const double*, const double* x1, const double* x2, const Index& idx, Hess<N>* Om, Hess<N>* dOm) {
    make_variable_in_place(Om[0], x1[0], idx(1, 0));
    make_variable_in_place(dOm[0], x2[0], idx(2, 0));
  }
};

template <>
struct SeededVelocity<SE2> {
  static constexpr bool available = true;
  using C = std::complex<double>;

  // s: 1, w1, w2 or w1², with its derivative in its variable j (−1: constant) and s_jj.
  struct Factor {
    double value = 1, slope = 0, curvature = 0;
    int j = -1;
  };

  // Adds T = C(w) s x (c[k] = C^(k)(w)) with x = xr + i xi at variables (ir, ii), w at iw, into
  // the real and imaginary parts (re, im).
  template <int N>
  static void add_term(const C* c, const Factor& s, C x, int ir, int ii, int iw, Hess<N>& re, Hess<N>& im) {
    using H = Hess<N>;
    const C I(0.0, 1.0);
    auto put_g = [&](int i, C z) {
      re.g[i] += z.real();
      im.g[i] += z.imag();
    };
    auto put_h = [&](int i, int j, C z) {
      const int k = i <= j ? H::at(i, j) : H::at(j, i);
      re.H[k] += z.real();
      im.H[k] += z.imag();
    };
    const C value = c[0] * s.value * x;
    re.v += value.real();
    im.v += value.imag();
    put_g(iw, c[1] * s.value * x);
    put_g(ir, c[0] * s.value);
    put_g(ii, I * c[0] * s.value);
    put_h(iw, iw, c[2] * s.value * x);
    put_h(iw, ir, c[1] * s.value);
    put_h(iw, ii, I * c[1] * s.value);
    if (s.j >= 0) {
      put_g(s.j, c[0] * s.slope * x);
      put_h(iw, s.j, c[1] * s.slope * x);
      put_h(ir, s.j, c[0] * s.slope);
      put_h(ii, s.j, I * c[0] * s.slope);
      if (s.curvature != 0.0) put_h(s.j, s.j, c[0] * s.curvature * x);
    }
  }

  template <int N, class Index>
  static void jet(const double* x0, const double* x1, const double* x2, const Index& idx, Hess<N>* Om, Hess<N>* dOm) {
    const double w = x0[2], w1 = x1[2], w2 = x2[2];
    const C v(x0[0], x0[1]), v1(x1[0], x1[1]), v2(x2[0], x2[1]);
    // a1, a2, b1, b2 and their derivatives to third order: D^k f = a[k] k!.
    const auto f = detail::se2_angle_functions(Poly<3>::variable(w));
    const double fact[4] = {1, 1, 2, 6};
    C A[4], B[4];
    for (int k = 0; k < 4; ++k) {
      A[k] = C(f[0].a[k], -f[1].a[k]) * fact[k];
      B[k] = C(f[2].a[k], f[3].a[k]) * fact[k];
    }
    const C P[3] = {A[1] + B[0], A[2] + B[1], A[3] + B[2]};
    const C* Bp = B + 1;  // B' and its derivatives
    const int iw = idx(0, 2), iw1 = idx(1, 2), iw2 = idx(2, 2);
    const Factor one{}, by_w1{w1, 1.0, 0.0, iw1}, by_w2{w2, 1.0, 0.0, iw2}, by_w1sq{w1 * w1, 2 * w1, 2.0, iw1};
    add_term(A, one, v1, idx(1, 0), idx(1, 1), iw, Om[0], Om[1]);
    add_term(B, by_w1, v, idx(0, 0), idx(0, 1), iw, Om[0], Om[1]);
    add_term(A, one, v2, idx(2, 0), idx(2, 1), iw, dOm[0], dOm[1]);
    add_term(P, by_w1, v1, idx(1, 0), idx(1, 1), iw, dOm[0], dOm[1]);
    add_term(B, by_w2, v, idx(0, 0), idx(0, 1), iw, dOm[0], dOm[1]);
    add_term(Bp, by_w1sq, v, idx(0, 0), idx(0, 1), iw, dOm[0], dOm[1]);
    make_variable_in_place(Om[2], w1, iw1);
    make_variable_in_place(dOm[2], w2, iw2);
  }
};

template <class A, class B>
struct SeededVelocity<Product<A, B>> {
  static constexpr bool available = SeededVelocity<A>::available && SeededVelocity<B>::available;
  template <int N, class Index>
  static void jet(const double* x0, const double* x1, const double* x2, const Index& idx, Hess<N>* Om, Hess<N>* dOm) {
    constexpr int da = A::dim;
    SeededVelocity<A>::template jet<N>(x0, x1, x2, idx, Om, dOm);
    const auto idx_b = [&](int k, int a) { return idx(k, da + a); };
    SeededVelocity<B>::template jet<N>(x0 + da, x1 + da, x2 + da, idx_b, Om + da, dOm + da);
  }
};

}  // namespace lpshoot
