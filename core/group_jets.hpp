// Velocities along group curves, for any of lpshoot's groups (used by the Galerkin schemes'
// group part, METHOD.md §9 route (a): g(t) = g_n exp(ξ(t)) with ξ a polynomial in the algebra).
//   body_velocity_jet: Ω and Ω' of exp(ξ(s)) at s = 0 from ξ, ξ', ξ'' there: by the group's
//     closed form (group_velocity.hpp), or generically through
//     log(exp(ξ(0))^{-1} exp(ξ(s))) = Ω s + Ω' s^2 / 2 + O(s^3);
//   right_jacobian: Jr(ζ) Y = d/dε log(exp(ζ)^{-1} exp(ζ + ε Y)), the body velocity of exp(ξ)
//     at ξ = ζ per unit ξ'.
#pragma once

#include "group_velocity.hpp"
#include "groups.hpp"
#include "hessian_scalar.hpp"
#include "scalar_tower.hpp"
#include "taylor.hpp"

#include <utility>

namespace lpshoot {

// The generic route: the group's exp, compose and log in Taylor2<T>, ξ(s) = ξ0 + ξ1 s + ξ2 s²/2.
template <class G, class T>
void body_velocity_jet_generic(const typename G::template Tangent<T>& xi0, const typename G::template Tangent<T>& xi1,
                               const typename G::template Tangent<T>& xi2, typename G::template Tangent<T>& Omega,
                               typename G::template Tangent<T>& dOmega) {
  using TT = Taylor2<T>;
  typename G::template Tangent<TT> xi;
  for (int a = 0; a < G::dim; ++a) xi(a) = TT(xi0(a), xi1(a), 0.5 * xi2(a));
  const auto start_inverse = G::template cast<TT>(G::inverse(G::template exp<T>(xi0)));
  const typename G::template Tangent<TT> rel = G::log(G::compose(start_inverse, G::template exp<TT>(xi)));
  for (int a = 0; a < G::dim; ++a) {
    Omega(a) = rel(a).c1;
    dOmega(a) = 2.0 * rel(a).c2;
  }
}

// Ω and Ω' of exp(ξ(s)) at s = 0 from ξ, ξ', ξ'' there: by the group's closed form where it has
// one (group_velocity.hpp), else generically.
template <class G, class T>
void body_velocity_jet(const typename G::template Tangent<T>& xi0, const typename G::template Tangent<T>& xi1,
                       const typename G::template Tangent<T>& xi2, typename G::template Tangent<T>& Omega,
                       typename G::template Tangent<T>& dOmega) {
  if constexpr (GroupVelocity<G>::closed_form)
    GroupVelocity<G>::template jet<T>(xi0, xi1, xi2, Omega, dOmega);
  else
    body_velocity_jet_generic<G, T>(xi0, xi1, xi2, Omega, dOmega);
}

// x = A^{-1} b for a small square A in any scalar (Gaussian elimination, partial pivoting on the
// double values).
template <class T, int n>
Eigen::Matrix<T, n, 1> solve_small(Eigen::Matrix<T, n, n> A, Eigen::Matrix<T, n, 1> b) {
  for (int c = 0; c < n; ++c) {
    int p = c;
    for (int i = c + 1; i < n; ++i)
      if (std::abs(value(A(i, c))) > std::abs(value(A(p, c)))) p = i;
    if (p != c) {
      A.row(c).swap(A.row(p));
      std::swap(b(c), b(p));
    }
    const T inv = T(1.0) / A(c, c);
    for (int i = c + 1; i < n; ++i) {
      const T f = A(i, c) * inv;
      for (int j = c + 1; j < n; ++j) A(i, j) = A(i, j) - f * A(c, j);
      b(i) = b(i) - f * b(c);
    }
  }
  Eigen::Matrix<T, n, 1> x;
  for (int i = n - 1; i >= 0; --i) {
    T s = b(i);
    for (int j = i + 1; j < n; ++j) s = s - A(i, j) * x(j);
    x(i) = s / A(i, i);
  }
  return x;
}

namespace detail {
template <class G, class T>
Eigen::Matrix<T, G::dim, G::dim> right_jacobian_direct(const typename G::template Tangent<T>& zeta) {
  constexpr int d = G::dim;
  using TD = Dual<T, d>;
  typename G::template Tangent<TD> z;
  for (int a = 0; a < d; ++a) z(a) = TD::variable(zeta(a), a);
  const auto start_inverse = G::template cast<TD>(G::inverse(G::template exp<T>(zeta)));
  const typename G::template Tangent<TD> rel = G::log(G::compose(start_inverse, G::template exp<TD>(z)));
  Eigen::Matrix<T, d, d> J;
  for (int i = 0; i < d; ++i)
    for (int j = 0; j < d; ++j) J(i, j) = rel(i).d[j];
  return J;
}
}  // namespace detail

template <class G, class T>
Eigen::Matrix<T, G::dim, G::dim> right_jacobian(const typename G::template Tangent<T>& zeta) {
  return detail::right_jacobian_direct<G, T>(zeta);
}

// Jr(ζ)^{-1}. In nested duals (first or second derivatives), from Jr^{-1} and its first and
// second derivatives in ζ computed in double duals of width d, then the chain rule
// (scalar_tower.hpp): the group's exp/log are not run in the nested type.
template <class G, class T>
Eigen::Matrix<T, G::dim, G::dim> right_jacobian_inverse(const typename G::template Tangent<T>& zeta) {
  constexpr int d = G::dim;
  constexpr int K = derivative_order<T>::value;
  auto invert = [](const auto& J) {
    using S = typename std::decay_t<decltype(J)>::Scalar;
    Eigen::Matrix<S, d, d> R;
    for (int j = 0; j < d; ++j) {
      Eigen::Matrix<S, d, 1> e = Eigen::Matrix<S, d, 1>::Constant(S(0.0));
      e(j) = S(1.0);
      R.col(j) = solve_small<S, d>(J, e);
    }
    return R;
  };
  if constexpr (K == 0 || K > 2 || !detail::is_dual_over_double<T, K>::value) {
    return invert(right_jacobian<G, T>(zeta));
  } else {
    using D = std::conditional_t<K == 1, Dual<double, d>, Dual<Dual<double, d>, d>>;
    typename G::template Tangent<D> z;
    for (int a = 0; a < d; ++a) {
      if constexpr (K == 1)
        z(a) = D::variable(value(zeta(a)), a);
      else
        z(a) = D::variable(Dual<double, d>::variable(value(zeta(a)), a), a);
    }
    const Eigen::Matrix<D, d, d> R = invert(detail::right_jacobian_direct<G, D>(z));
    Eigen::Matrix<T, d, d> out;
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j) {
        if constexpr (detail::is_hess<T>::value)
          out(i, j) = detail::lift_multivariate_hess<detail::is_hess<T>::width>(R(i, j), zeta);
        else
          out(i, j) = detail::lift_multivariate<T>(R(i, j), zeta);
      }
    return out;
  }
}

// Jr(ζ)^{-1} y: by the group's closed form where it has one (group_velocity.hpp).
template <class G, class T>
typename G::template Tangent<T> right_jacobian_inverse_times(const typename G::template Tangent<T>& zeta,
                                                             const typename G::template Tangent<T>& y) {
  if constexpr (GroupVelocity<G>::closed_form)
    return GroupVelocity<G>::template right_jacobian_inverse_times<T>(zeta, y);
  else
    return right_jacobian_inverse<G, T>(zeta) * y;
}

}  // namespace lpshoot
