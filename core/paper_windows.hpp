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
// The flow keeps the nodes to twice the working precision (keeps_low_parts, compensated.hpp)
// and the jet takes its differences from both parts (Window::low_difference): Δp and Δ²p are
// formed to their own precision, never from nodes rounded to doubles, so the recursion does not
// amplify the nodes' rounding (METHOD.md §9; bench/RESULTS.md, "The paper's windows without
// their roundoff floor").
#pragma once

#include "continuous.hpp"
#include "group_element_scalars.hpp"
#include "hessian_scalar.hpp"
#include "problem.hpp"

namespace lpshoot {

enum class WindowJet { Forward, Central };

// Low = false: the nodes are rounded to doubles as in a hand-written L_d (for comparison only).
template <class C, WindowJet J = WindowJet::Central, bool Low = true>
struct PaperWindows {
  using Model = C;
  using Group = typename C::Group;
  static constexpr int shape_dim = C::shape_dim;
  static constexpr int order = 2;
  static constexpr int num_constraints = C::num_constraints;
  static constexpr WindowJet jet_kind = J;
  static constexpr bool keeps_low_parts = Low;
  C model;

  // q_n of the file comment.
  template <class T>
  Jet<C, T> jet(const Window<PaperWindows, T>& a, double h) const {
    Jet<C, T> q;
    const Vec<T, shape_dim> d0 = a.low_difference(1, 0), d1 = a.low_difference(2, 1);
    // Δ²p from the nodes' exact differences: (p2 - p1) - (p1 - p0) rounds once, relative to Δ²p.
    const Vec<T, shape_dim> dd = ((a.p[2] - a.p[1]) - (a.p[1] - a.p[0])) +
                                 (a.p_low[2] - 2.0 * a.p_low[1] + a.p_low[0]).template cast<T>();
    q.ddp = dd / (h * h);
    if constexpr (J == WindowJet::Forward) {
      q.p = a.p[0];
      q.dp = d0 / h;
    } else {
      q.p = a.p[1];
      q.dp = (d0 + d1) / (2.0 * h);
    }
    if constexpr (Group::dim > 0) {
      const Vec<T, Group::dim> w0 = reduced_velocity(a.p[0], a.p[1], d0, a.g[0], h),
                               w1 = reduced_velocity(a.p[1], a.p[2], d1, a.g[1], h);
      if constexpr (J == WindowJet::Forward)
        q.Omega = w0;
      else
        q.Omega = 0.5 * (w0 + w1);
      q.dOmega = (w1 - w0) / h;
    }
    return q;
  }

  // ω_j of the file comment, from increment g~ = W A(p0, p1) over [p0, p1], dp = p1 - p0.
  template <class T>
  Vec<T, Group::dim> reduced_velocity(const Vec<T, shape_dim>& p0, const Vec<T, shape_dim>& p1, const Vec<T, shape_dim>& dp,
                                      const typename Group::template Element<T>& g, double h) const {
    constexpr int r = shape_dim;
    if constexpr (detail::is_hess<T>::value && has_element_scalars<Group>()) {
      // A window's Hessian (step_window_hessian.hpp): ω depends on its 3r + s arguments only (s
      // the element's scalars), so its group operations run in Hess<3r + s> and are composed.
      constexpr int N = detail::is_hess<T>::width, s = ElementScalars<Group>::count, M = 3 * r + s;
      if constexpr (M < N) {
        auto gc = g;
        const auto gs = ElementScalars<Group>::of(gc);
        std::array<const T*, M> x;
        for (int c = 0; c < r; ++c) x[c] = &p0(c), x[r + c] = &p1(c), x[2 * r + c] = &dp(c);
        for (int c = 0; c < s; ++c) x[3 * r + c] = gs[c];
        return detail::compose_through<N, M, Group::dim>(x, [&](const std::array<Hess<M>, M>& y) {
          Vec<Hess<M>, r> q0, q1, dq;
          for (int c = 0; c < r; ++c) q0(c) = y[c], q1(c) = y[r + c], dq(c) = y[2 * r + c];
          auto gm = Group::template identity<Hess<M>>();
          const auto gms = ElementScalars<Group>::of(gm);
          for (int c = 0; c < s; ++c) *gms[c] = y[3 * r + c];
          return reduced_velocity<Hess<M>>(q0, q1, dq, gm, h);
        });
      }
    }
    if constexpr (detail::HasConnectionForm<C, T>::value) {
      const Vec<T, Group::dim> a = connection_velocity(model, Vec<T, shape_dim>(0.5 * (p0 + p1)), dp);
      const auto W = Group::compose(g, Group::inverse(Group::template exp<T>(a)));
      return (Group::log(W) + a) / h;
    } else {
      (void)p0, (void)p1, (void)dp;
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
  // The natural boundary conditions' missing half window (bench/RESULTS.md, "Second-order
  // natural conditions on the derived windows"). The windows' sum is a midpoint rule on [h/2, T − h/2]: its truncated node
  // residuals at a free end are the continuous natural conditions at h/2, first order. With
  // G = ∇(h ℓ + λ·χ) in the jet's p, p', Ω at the end window (frozen: end_slopes), adding to
  // a free end node's residual the gradient of
  //   K = ½ [G_p·p_e + G_p'·(p_{e+} − p_{e−})/h + G_Ω·ω_e]
  // (e the end node, (p_{e−}, p_{e+}) and ω_e the end interval's nodes and velocity) restores
  // what the linearized ∫ over [0, h/2] (or [T − h/2, T]) contributes. By Taylor expansion the
  // rows become π₂ = ℓ̃_p'' and π₁ = ℓ̃_p' − (ℓ̃_p'')' at the end (and for Ω: ℓ̃_Ω' and the
  // momentum) to O(h²). Central jet only: the forward jet is first order anyway.
  static constexpr bool has_half_window = J == WindowJet::Central;
  template <class T>
  struct Slopes {
    Vec<T, shape_dim> p, dp;
    Vec<T, Group::dim> Omega;
  };
  template <class T>
  Slopes<T> end_slopes(const Window<PaperWindows, T>& a, const Vec<T, num_constraints>& lam, double h) const {
    constexpr int r = shape_dim, d = Group::dim;
    using TD = Dual<T, 2 * r + d>;
    const Jet<C, T> q = jet(a, h);
    Jet<C, TD> x;
    x.p = q.p.template cast<TD>(), x.dp = q.dp.template cast<TD>(), x.ddp = q.ddp.template cast<TD>();
    x.Omega = q.Omega.template cast<TD>(), x.dOmega = q.dOmega.template cast<TD>();
    for (int i = 0; i < r; ++i) x.p(i) = TD::variable(q.p(i), i), x.dp(i) = TD::variable(q.dp(i), r + i);
    for (int i = 0; i < d; ++i) x.Omega(i) = TD::variable(q.Omega(i), 2 * r + i);
    TD L = h * model.template lagrangian<TD>(x);
    if constexpr (num_constraints > 0) {
      const Vec<TD, num_constraints> chi = model_constraints(model, x);
      for (int i = 0; i < num_constraints; ++i) L = L + TD(lam(i)) * chi(i);
    }
    Slopes<T> s;
    for (int i = 0; i < r; ++i) s.p(i) = L.d[i], s.dp(i) = L.d[r + i];
    for (int i = 0; i < d; ++i) s.Omega(i) = L.d[2 * r + i];
    return s;
  }
  // K on the end window a (the first window for the initial end, the last for the terminal).
  template <class T, class S>
  T half_window(const Window<PaperWindows, T>& a, const Slopes<S>& s, bool initial, double h) const {
    const int e = initial ? 0 : 2, lo = initial ? 0 : 1;
    T K = T(0.0);
    const Vec<T, shape_dim> dp = a.low_difference(lo + 1, lo);
    for (int i = 0; i < shape_dim; ++i) K = K + T(s.p(i)) * a.p[e](i) + T(s.dp(i)) * dp(i) / h;
    if constexpr (Group::dim > 0) {
      const Vec<T, Group::dim> w = reduced_velocity(a.p[lo], a.p[lo + 1], dp, a.g[lo], h);
      for (int i = 0; i < Group::dim; ++i) K = K + T(s.Omega(i)) * w(i);
    }
    return 0.5 * K;
  }

  // Only when the model has a connection form (otherwise the bundle is trivial: problem.hpp).
  template <class T, class CC = C, std::enable_if_t<detail::HasConnectionForm<CC, T>::value, int> = 0>
  typename Group::template Element<T> connection(const Vec<T, shape_dim>& p0, const Vec<T, shape_dim>& p1) const {
    const Vec<T, shape_dim> mid = 0.5 * (p0 + p1), dp = p1 - p0;
    return Group::template exp<T>(connection_velocity(model, mid, dp));
  }
};

}  // namespace lpshoot
