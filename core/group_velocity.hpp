// Closed forms of the body velocity along a group curve exp(ξ(s)), for the groups lpshoot
// offers (used by group_jets.hpp's body_velocity_jet, METHOD.md §9 route (a)).
//
// With ξ(s) = ξ0 + ξ1 s + ξ2 s²/2, the body velocity Ω(s) = exp(ξ)^{-1} d/ds exp(ξ) = Jr(ξ) ξ'
// and its derivative at s = 0 are
//   Ω = Jr(ξ0) ξ1,  Ω' = DJr(ξ0)[ξ1] ξ1 + Jr(ξ0) ξ2.
// The generic route runs the group's exp/log in Taylor arithmetic of the engine's scalar (nested
// duals or Hess, up to 17 directions); these closed forms need a few scalar functions of one
// angle, lifted by their derivatives (scalar_tower.hpp), and a few dozen products.
//   R^n, SO(2): Ω = ξ1, Ω' = ξ2 (abelian, Jr = I).
//   SE(2), ξ = (v, w) (group_se2.hpp's coordinates), J the rotation by π/2:
//     exp(ξ) = (w, V(w) v), V = a1 I + a2 J, so with the rotation R(w) and A = R(-w) V(w),
//     B = R(-w) V'(w):
//       Ω_w = w1,  Ω_v = A v1 + w1 B v,
//       Ω'_w = w2, Ω'_v = w1 A' v1 + A v2 + w2 B v + w1² B' v + w1 B v1,
//     where A = a1 I - a2 J, B = b1 I + b2 J with a1 = sin w / w, a2 = (1 - cos w) / w,
//     b1 = (w - sin w) / w², b2 = (1 - cos w) / w² (V ≅ (e^{iw} - 1)/(iw) as a complex number,
//     A its conjugate, B = e^{-iw} V'(w)).
//   Product: componentwise.
// The same structure inverts Jr (right_jacobian_inverse_times, the Galerkin curve's end slope):
//   R^n, SO(2): Jr = I;  SE(2): Jr(ξ)(y_v, y_w) = (A y_v + y_w B v, y_w), so
//   Jr(ξ)^{-1}(y_v, y_w) = (A^{-1}(y_v - y_w B v), y_w),  A^{-1} ≅ (w/2) cot(w/2) + i w/2.
// Groups without a closed form keep the generic route (GroupVelocity<G>::closed_form false).
#pragma once

#include "group_series.hpp"
#include "groups.hpp"

#include <array>
#include <utility>

namespace lpshoot {

template <class G>
struct GroupVelocity {
  static constexpr bool closed_form = false;
};

namespace detail {

// f_i(x) and f_i'(x) for M functions written once generically (impl(y) returns them as a
// std::array, in double or Poly, so that they can share work), lifted to x's type.
template <int M, class T, class F>
std::array<std::pair<T, T>, M> apply_univariate_with_slope(const T& x, F&& impl) {
  std::array<std::pair<T, T>, M> out;
  if constexpr (std::is_same_v<T, double>) {
    const auto p = impl(Poly<1>::variable(x));
    for (int i = 0; i < M; ++i) out[i] = {p[i].a[0], p[i].a[1]};
  } else {
    constexpr int K = derivative_order<T>::value;
    const auto p = impl(Poly<K + 1>::variable(value(x)));
    for (int i = 0; i < M; ++i) {
      double f[K + 2];
      double fact = 1.0;
      for (int k = 0; k <= K + 1; ++k) {
        if (k > 0) fact *= k;
        f[k] = p[i].a[k] * fact;
      }
      out[i] = {lift(f, x), lift(f + 1, x)};
    }
  }
  return out;
}

// (w - sin w) / w², by its series w Σ_j (-1)^j w^(2j) / (2j + 3)! for |w| < 1 (the closed form
// loses ~6/w² ulps to cancellation).
template <class T>
T se2_b1_value(const T& w) {
  using std::sin;
  if (std::abs(value(w)) < 1.0) return w * alternating_series(w, 2);
  return (w - sin(w)) / (w * w);
}

// (1 - cos w) / w² = cosc(w) / w, by its series for |w| < 0.5 and 2 sin²(w/2) / w² otherwise.
template <class T>
T se2_b2_value(const T& w) {
  using std::sin;
  if (std::abs(value(w)) < kSeriesRadius) return alternating_series(w, 1);
  const T s = sin(w * 0.5);
  return 2.0 * s * s / (w * w);
}

// SE(2)'s four functions of the angle (a1, a2, b1, b2) = (sinc w, cosc w, (w - sin w) / w²,
// (1 - cos w) / w²), as se2_b1_value etc. would give them one by one, with the shared work
// done once: b2 = a2 / w is the same series (or the same sine).
template <class T>
std::array<T, 4> se2_angle_functions(const T& w) {
  using std::sin;
  std::array<T, 4> f;
  if (std::abs(value(w)) < kSeriesRadius) {
    f[0] = alternating_series(w, 0);
    f[3] = alternating_series(w, 1);
    f[1] = w * f[3];
  } else {
    const T s = sin(w * 0.5);
    f[0] = sin(w) / w;
    f[1] = 2.0 * s * s / w;
    f[3] = f[1] / w;
  }
  f[2] = se2_b1_value(w);
  return f;
}

// (w/2) cot(w/2), by its series Σ_n c_n w^(2n) (from the Bernoulli numbers) for |w| < 0.5 and
// the closed form otherwise (no cancellation there).
template <class T>
T se2_half_cot_value(const T& w) {
  using std::cos;
  using std::sin;
  if (std::abs(value(w)) < kSeriesRadius) {
    static constexpr double c[kSeriesTerms] = {1.0,
                                     -1.0 / 12.0,
                                     -1.0 / 720.0,
                                     -1.0 / 30240.0,
                                     -1.0 / 1209600.0,
                                     -1.0 / 47900160.0,
                                     -691.0 / 1307674368000.0,
                                     -1.0 / 74724249600.0,
                                     -3617.0 / 10670622842880000.0,
                                     -43867.0 / 5109094217170944000.0};
    return trimmed_series<T, 3>(w, c);
  }
  const T half = w * 0.5;
  return half * cos(half) / sin(half);
}

// (α I + β J) x for J the rotation by π/2: (α x0 - β x1, β x0 + α x1).
template <class T>
Eigen::Matrix<T, 2, 1> complex_times(const T& alpha, const T& beta, const Eigen::Matrix<T, 2, 1>& x) {
  return {alpha * x(0) - beta * x(1), beta * x(0) + alpha * x(1)};
}

// acc += (α I + s β J) x, s = ±1, products accumulated in place.
template <class T>
void add_complex_times(Eigen::Matrix<T, 2, 1>& acc, const T& alpha, double s, const T& beta,
                       const Eigen::Matrix<T, 2, 1>& x) {
  add_product(acc(0), 1.0, alpha, x(0));
  add_product(acc(0), -s, beta, x(1));
  add_product(acc(1), s, beta, x(0));
  add_product(acc(1), 1.0, alpha, x(1));
}

}  // namespace detail

template <int N>
struct GroupVelocity<Rn<N>> {
  static constexpr bool closed_form = true;
  template <class T>
  static void jet(const typename Rn<N>::template Tangent<T>&, const typename Rn<N>::template Tangent<T>& x1, const typename Rn<N>::template Tangent<T>& x2, typename Rn<N>::template Tangent<T>& Om, typename Rn<N>::template Tangent<T>& dOm) {
    Om = x1;
    dOm = x2;
  }
  template <class T>
  static typename Rn<N>::template Tangent<T> right_jacobian_inverse_times(const typename Rn<N>::template Tangent<T>&, const typename Rn<N>::template Tangent<T>& y) {
    return y;
  }
};

template <>
struct GroupVelocity<SO2> {
  static constexpr bool closed_form = true;
  template <class T>
  static void jet(const SO2::Tangent<T>&, const SO2::Tangent<T>& x1, const SO2::Tangent<T>& x2, SO2::Tangent<T>& Om, SO2::Tangent<T>& dOm) {
    Om = x1;
    dOm = x2;
  }
  template <class T>
  static SO2::Tangent<T> right_jacobian_inverse_times(const SO2::Tangent<T>&, const SO2::Tangent<T>& y) {
    return y;
  }
};

template <>
struct GroupVelocity<SE2> {
  static constexpr bool closed_form = true;
  template <class T>
  static void jet(const SE2::Tangent<T>& x0, const SE2::Tangent<T>& x1, const SE2::Tangent<T>& x2, SE2::Tangent<T>& Om, SE2::Tangent<T>& dOm) {
    using V2 = Eigen::Matrix<T, 2, 1>;
    const T& w = x0(2);
    const T &w1 = x1(2), &w2 = x2(2);
    const V2 v = x0.template head<2>(), v1 = x1.template head<2>(), v2 = x2.template head<2>();
    const auto fs = detail::apply_univariate_with_slope<4>(w, [](const auto& y) { return detail::se2_angle_functions(y); });
    const auto& [a1, da1] = fs[0];
    const auto& [a2, da2] = fs[1];
    const auto& [b1, db1] = fs[2];
    const auto& [b2, db2] = fs[3];
    // Ω_v = A v1 + (w1 B) v;  Ω'_v = A v2 + (w1 (A' + B)) v1 + (w2 B + w1² B') v.
    const T wb1 = w1 * b1, wb2 = w1 * b2;
    const T wp1 = w1 * (da1 + b1), wp2 = w1 * (b2 - da2);
    const T w1sq = w1 * w1;
    T q1 = w2 * b1, q2 = w2 * b2;
    add_product(q1, 1.0, w1sq, db1);
    add_product(q2, 1.0, w1sq, db2);
    V2 o = V2::Constant(T(0.0)), d = V2::Constant(T(0.0));
    detail::add_complex_times(o, a1, -1.0, a2, v1);
    detail::add_complex_times(o, wb1, 1.0, wb2, v);
    detail::add_complex_times(d, a1, -1.0, a2, v2);
    detail::add_complex_times(d, wp1, 1.0, wp2, v1);
    detail::add_complex_times(d, q1, 1.0, q2, v);
    Om.template head<2>() = o;
    Om(2) = w1;
    dOm.template head<2>() = d;
    dOm(2) = w2;
  }
  template <class T>
  static SE2::Tangent<T> right_jacobian_inverse_times(const SE2::Tangent<T>& zeta, const SE2::Tangent<T>& y) {
    using V2 = Eigen::Matrix<T, 2, 1>;
    const T& w = zeta(2);
    const T b1 = detail::apply_univariate(w, [](const auto& u) { return detail::se2_b1_value(u); });
    const T b2 = detail::apply_univariate(w, [](const auto& u) { return detail::se2_b2_value(u); });
    const T alpha = detail::apply_univariate(w, [](const auto& u) { return detail::se2_half_cot_value(u); });
    const V2 rhs = y.template head<2>() - y(2) * detail::complex_times(b1, b2, V2(zeta.template head<2>()));
    SE2::Tangent<T> x;
    x.template head<2>() = detail::complex_times(alpha, T(0.5 * w), rhs);
    x(2) = y(2);
    return x;
  }
};

template <class A, class B>
struct GroupVelocity<Product<A, B>> {
  static constexpr bool closed_form = GroupVelocity<A>::closed_form && GroupVelocity<B>::closed_form;
  static constexpr int da = A::dim, db = B::dim;
  template <class T>
  static void jet(const typename Product<A, B>::template Tangent<T>& x0, const typename Product<A, B>::template Tangent<T>& x1, const typename Product<A, B>::template Tangent<T>& x2,
                  typename Product<A, B>::template Tangent<T>& Om, typename Product<A, B>::template Tangent<T>& dOm) {
    typename A::template Tangent<T> Oa, dOa;
    typename B::template Tangent<T> Ob, dOb;
    GroupVelocity<A>::template jet<T>(x0.template head<da>(), x1.template head<da>(), x2.template head<da>(), Oa, dOa);
    GroupVelocity<B>::template jet<T>(x0.template tail<db>(), x1.template tail<db>(), x2.template tail<db>(), Ob, dOb);
    Om.template head<da>() = Oa;
    Om.template tail<db>() = Ob;
    dOm.template head<da>() = dOa;
    dOm.template tail<db>() = dOb;
  }
  template <class T>
  static typename Product<A, B>::template Tangent<T> right_jacobian_inverse_times(const typename Product<A, B>::template Tangent<T>& zeta, const typename Product<A, B>::template Tangent<T>& y) {
    typename Product<A, B>::template Tangent<T> x;
    x.template head<da>() = GroupVelocity<A>::template right_jacobian_inverse_times<T>(zeta.template head<da>(), y.template head<da>());
    x.template tail<db>() = GroupVelocity<B>::template right_jacobian_inverse_times<T>(zeta.template tail<db>(), y.template tail<db>());
    return x;
  }
};

}  // namespace lpshoot
