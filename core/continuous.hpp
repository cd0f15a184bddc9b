// The continuous reduced problem (METHOD.md §9): what a user states once, before choosing a
// discretization. A second-order reduced Lagrangian ℓ(p, p', p'', Ω) and, when the problem needs
// them, constraints χ(p, p', p'', Ω, Ω') = 0 and the local form 𝒜(p) of a principal connection:
//
//   struct MyModel {
//     using Group = lpshoot::SE2;                  // G (lpshoot::Trivial: no symmetry)
//     static constexpr int shape_dim = 1;          // r
//     static constexpr int num_constraints = 3;    // m
//     template <class T> T lagrangian(const lpshoot::Jet<MyModel, T>& q) const;
//     template <class T> lpshoot::Vec<T, 3> constraints(const lpshoot::Jet<MyModel, T>& q) const;  // m > 0
//     template <class T> Eigen::Matrix<T, 3, 1> connection_form(const lpshoot::Vec<T, 1>& p) const;  // optional
//   };
//
// Ω is the reduced group velocity g^{-1} g' + 𝒜(p) p' (body coordinates, the group's algebra
// basis). The engine differentiates these functions: write them with T arithmetic only.
#pragma once

#include "problem.hpp"

namespace lpshoot {

template <class C, class T>
struct Jet {
  Vec<T, C::shape_dim> p, dp, ddp;                  // p, p', p''
  Vec<T, C::Group::dim> Omega, dOmega;              // Ω, Ω'
};

namespace detail {
template <class C, class T, class = void>
struct HasConnectionForm : std::false_type {};
template <class C, class T>
struct HasConnectionForm<C, T,
                         std::void_t<decltype(std::declval<const C&>().template connection_form<T>(
                             std::declval<const Vec<T, C::shape_dim>&>()))>> : std::true_type {};
}  // namespace detail

// 𝒜(p) p' (zero without a connection form).
template <class C, class T>
Vec<T, C::Group::dim> connection_velocity(const C& model, const Vec<T, C::shape_dim>& p, const Vec<T, C::shape_dim>& dp) {
  if constexpr (detail::HasConnectionForm<C, T>::value) {
    const Eigen::Matrix<T, C::Group::dim, C::shape_dim> A = model.template connection_form<T>(p);
    return A * dp;
  } else {
    (void)model, (void)p, (void)dp;
    return Vec<T, C::Group::dim>::Constant(T(0.0));
  }
}

template <class C, class T>
Vec<T, C::num_constraints> model_constraints(const C& model, const Jet<C, T>& q) {
  if constexpr (C::num_constraints > 0) {
    return model.template constraints<T>(q);
  } else {
    (void)model, (void)q;
    return Vec<T, 0>();
  }
}

}  // namespace lpshoot
