// The paper's nodal windows from a continuous model (issue 13; METHOD.md §2, §8, §9): a user
// states ℓ (and χ, 𝒜) once, as for the Galerkin schemes, and gets a discrete problem of order
// k = 2 for the engine's flow, momentum and shooting (problem.hpp's contract), with nothing
// written by hand. On window a_n = (p_n, p_{n+1}, p_{n+2}, g~_n, g~_{n+1}):
//   L_d(a_n) = h ℓ(q_n),   χ_d(a_n) = χ(q_n),
// with q_n a jet of finite differences, the discrete connection
//   A(p0, p1) = exp(a),  a = 𝒜((p0 + p1)/2) (p1 − p0)    (the beanie's eq. (74) when 𝒜 is constant)
// and the reduced velocity of increment j, g~_j = W_j A_j (W_j = g_j^{-1} g_{j+1}),
//   ω_j = (log W_j + a_j) / h  =  Ω(t_{j+1/2}) + O(h²),   Ω = g^{-1} g' + 𝒜(p) p'
// (log g~_j / h is only first order: by Baker–Campbell–Hausdorff it adds ½ [log W_j, a_j] / h).
// L_d depends on the group only through g~: the discrete momentum map is conserved (§4).
//
//   Forward (the paper's electron L_d, eq. (64) with m):
//     q_n = (p_n, Δp_n/h, Δ²p_n/h², ω_n, (ω_{n+1} − ω_n)/h): first order;
//     constraints linear in Ω' become forward Euler, as the paper's (80)–(82).
//   Central (METHOD.md §8's symmetric scheme: every entry at t_{n+1}):
//     q_n = (p_{n+1}, (p_{n+2} − p_n)/(2h), Δ²p_n/h², (ω_n + ω_{n+1})/2, (ω_{n+1} − ω_n)/h);
//     with ℓ = ½ u(p, p'') this is the paper's beanie L^_d (79), and constraints linear in Ω'
//     become trapezoidal.
// Both keep the nodal state (the roundoff of nearly equal nodes, METHOD.md §9); the Galerkin
// schemes do not have it.
#pragma once

#include "continuous.hpp"
#include "problem.hpp"

namespace lpshoot {

enum class WindowJet { Forward, Central };

template <class C, WindowJet J = WindowJet::Central>
struct PaperWindows {
  using Model = C;
  using Group = typename C::Group;
  static constexpr int shape_dim = C::shape_dim;
  static constexpr int order = 2;
  static constexpr int num_constraints = C::num_constraints;
  static constexpr WindowJet jet_kind = J;
  C model;

  // q_n of the file comment.
  template <class T>
  Jet<C, T> jet(const Window<PaperWindows, T>& a, double h) const {
    Jet<C, T> q;
    const Vec<T, shape_dim> d0 = a.p[1] - a.p[0], d1 = a.p[2] - a.p[1];
    q.ddp = (d1 - d0) / (h * h);
    if constexpr (J == WindowJet::Forward) {
      q.p = a.p[0];
      q.dp = d0 / h;
    } else {
      q.p = a.p[1];
      q.dp = (d0 + d1) / (2.0 * h);
    }
    if constexpr (Group::dim > 0) {
      const Vec<T, Group::dim> w0 = reduced_velocity(a.p[0], a.p[1], a.g[0], h), w1 = reduced_velocity(a.p[1], a.p[2], a.g[1], h);
      if constexpr (J == WindowJet::Forward)
        q.Omega = w0;
      else
        q.Omega = 0.5 * (w0 + w1);
      q.dOmega = (w1 - w0) / h;
    }
    return q;
  }

  // ω_j of the file comment, from increment g~ = W A(p0, p1) over [p0, p1].
  template <class T>
  Vec<T, Group::dim> reduced_velocity(const Vec<T, shape_dim>& p0, const Vec<T, shape_dim>& p1,
                                      const typename Group::template Element<T>& g, double h) const {
    if constexpr (detail::HasConnectionForm<C, T>::value) {
      const Vec<T, Group::dim> a = connection_velocity(model, Vec<T, shape_dim>(0.5 * (p0 + p1)), Vec<T, shape_dim>(p1 - p0));
      const auto W = Group::compose(g, Group::inverse(Group::template exp<T>(a)));
      return (Group::log(W) + a) / h;
    } else {
      return Group::log(g) / h;
    }
  }

  template <class T>
  T lagrangian(const Window<PaperWindows, T>& a, double h) const {
    return h * model.template lagrangian<T>(jet(a, h));
  }
  template <class T>
  Vec<T, num_constraints> constraints(const Window<PaperWindows, T>& a, double h) const {
    return model_constraints(model, jet(a, h));
  }
  // Only when the model has a connection form (otherwise the bundle is trivial: problem.hpp).
  template <class T, class CC = C, std::enable_if_t<detail::HasConnectionForm<CC, T>::value, int> = 0>
  typename Group::template Element<T> connection(const Vec<T, shape_dim>& p0, const Vec<T, shape_dim>& p1) const {
    const Vec<T, shape_dim> mid = 0.5 * (p0 + p1), dp = p1 - p0;
    return Group::template exp<T>(connection_velocity(model, mid, dp));
  }
};

}  // namespace lpshoot
