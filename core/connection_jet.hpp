// The connection's part of the reduced velocity on a Galerkin curve (METHOD.md §9): Ω = ξ + 𝒜(p) p'
// and its time derivative, in the engine's scalar types.
//   connection_jet_generic: 𝒜(p) p' in Dual<T, 1> (first order in time: Ω' needs one derivative).
//   constant_connection: whether 𝒜 is constant to the order T's derivatives need (its
//     derivatives at p to order K + 1 vanish, K = T's derivative order; the time derivative takes
//     one more), checked in double duals. Then 𝒜 p' is a double matrix times T: the beanie's
//     𝒜 = (0, 0, c) costs no product of derivative-carrying scalars.
#pragma once

#include "continuous.hpp"
#include "hessian_scalar.hpp"
#include "scalar_tower.hpp"

namespace lpshoot {

namespace detail {
// x has no derivative part (every level's directions zero).
inline bool derivative_free(double) { return true; }
template <class T, int N>
bool derivative_free(const Dual<T, N>& x) {
  if (!derivative_free(x.v)) return false;
  for (const T& e : x.d)
    if (value(e) != 0.0 || !derivative_free(e)) return false;
  return true;
}
}  // namespace detail

// 𝒜(p) p' and its time derivative D𝒜(p)[p'] p' + 𝒜(p) p'', in Dual<T, 1> (first order in time).
template <class C, class T>
void connection_jet_generic(const C& model, const Vec<T, C::shape_dim>& p, const Vec<T, C::shape_dim>& dp,
                            const Vec<T, C::shape_dim>& ddp, Vec<T, C::Group::dim>& cv, Vec<T, C::Group::dim>& dcv) {
  using T1 = Dual<T, 1>;
  Vec<T1, C::shape_dim> pT, dpT;
  for (int a = 0; a < C::shape_dim; ++a) {
    pT(a).v = p(a);
    pT(a).d[0] = dp(a);
    dpT(a).v = dp(a);
    dpT(a).d[0] = ddp(a);
  }
  const Vec<T1, C::Group::dim> c = connection_velocity(model, pT, dpT);
  for (int i = 0; i < C::Group::dim; ++i) cv(i) = c(i).v, dcv(i) = c(i).d[0];
}

// Whether 𝒜 is constant to the order a scalar T's derivatives need, and its value: its
// derivatives at value(p) to order K + 1 vanish (K = T's derivative order; the time derivative
// of 𝒜(p) p' takes one more), checked in double duals. Then 𝒜 p' is a double matrix times T.
template <class C, class T>
bool constant_connection(const C& model, const Vec<T, C::shape_dim>& p,
                         Eigen::Matrix<double, C::Group::dim, C::shape_dim>& A0) {
  constexpr int r = C::shape_dim, d = C::Group::dim;
  if constexpr (derivative_order<T>::value > 2) {
    return false;
  } else {
    using P = Dual<Dual<Dual<double, r>, r>, r>;
    Vec<P, r> pp;
    for (int a = 0; a < r; ++a)
      pp(a) = P::variable(Dual<Dual<double, r>, r>::variable(Dual<double, r>::variable(value(p(a)), a), a), a);
    const Eigen::Matrix<P, d, r> A = model.template connection_form<P>(pp);
    for (int i = 0; i < d; ++i)
      for (int k = 0; k < r; ++k) {
        if (!detail::derivative_free(A(i, k))) return false;
        A0(i, k) = value(A(i, k));
      }
    return true;
  }
}

// A0 x for a double matrix and a vector of T, skipping zero entries.
template <class T, int d, int r>
Vec<T, d> double_matrix_times(const Eigen::Matrix<double, d, r>& A0, const Vec<T, r>& x) {
  Vec<T, d> y;
  for (int i = 0; i < d; ++i) {
    y(i) = T(0.0);
    for (int k = 0; k < r; ++k)
      if (A0(i, k) != 0.0) add_scaled(y(i), A0(i, k), x(k));
  }
  return y;
}

// 𝒜(p) p' with the constant shortcut.
template <class C, class T>
Vec<T, C::Group::dim> connection_velocity_of(const C& model, const Vec<T, C::shape_dim>& p,
                                             const Vec<T, C::shape_dim>& dp) {
  if constexpr (detail::HasConnectionForm<C, T>::value) {
    Eigen::Matrix<double, C::Group::dim, C::shape_dim> A0;
    if (constant_connection(model, p, A0)) return double_matrix_times(A0, dp);
  }
  return connection_velocity(model, p, dp);
}

// The jet of 𝒜(p) p' with the constant shortcut: 𝒜 p' and 𝒜 p''.
template <class C, class T>
void connection_jet(const C& model, const Vec<T, C::shape_dim>& p, const Vec<T, C::shape_dim>& dp,
                    const Vec<T, C::shape_dim>& ddp, Vec<T, C::Group::dim>& cv, Vec<T, C::Group::dim>& dcv) {
  Eigen::Matrix<double, C::Group::dim, C::shape_dim> A0;
  if (constant_connection(model, p, A0)) {
    cv = double_matrix_times(A0, dp);
    dcv = double_matrix_times(A0, ddp);
  } else {
    connection_jet_generic(model, p, dp, ddp, cv, dcv);
  }
}

}  // namespace lpshoot
