// The paper scheme's step derivatives from each window's Hessian, computed once and shared by
// the k + 1 steps whose equations contain the window (issue 9; METHOD.md §2–§3).
//
// Step n's node equation is E_n = Σ_{j = n-k..n} ∂_ε L~(a_j after node n moves by ε = (δp, η))
// (local_action.hpp). Window a_j's coordinates x are the state's tangent coordinates: nodes
// p + δp, increments g~ exp(δ), multipliers λ + δλ. Let y(x, ε) be the window's coordinates after
// the node perturbation, y(x, 0) = x. At the solved point, by the chain rule,
//   ∂E_n/∂x = Bᵀ H + Σ_q g_q C_q,   B = ∂y/∂ε,  C_q = ∂²y_q/∂ε∂x,
// with g and H the gradient and Hessian of L~(a_j) in x. g and H depend on the window alone: a_n's
// are computed at step n (when its unknowns are solved) and reused at steps n+1 .. n+k. Only the
// two increments next to node n move with ε (through the connection they also depend on their
// ends), so B and C are two small nested-dual passes over group operations, shared by the
// windows. χ_d(a_n)'s derivatives are H's λ rows: ∂²L~/∂λ∂x = ∂χ_d/∂x.
// Per step: one pass in Hess arithmetic (hessian_scalar.hpp) instead of k + 1 nested-dual passes
// of the windows in their nw directions (evaluate_step_by_window, kept as the reference).
#pragma once

#include "group_element_scalars.hpp"
#include "hessian_scalar.hpp"
#include "local_action.hpp"
#include "taped_hessian.hpp"

#include <array>

namespace lpshoot {

// A window's coordinates: its k+1 nodes (r each), k increments (d each), then λ (m).
template <class P>
constexpr int window_coordinates() {
  return (P::order + 1) * P::shape_dim + P::order * P::Group::dim + P::num_constraints;
}

// Above this many coordinates a Hess scalar is too large for the stack to pay; the step's
// derivatives are then taken window by window in nested duals.
template <class P>
constexpr bool uses_window_hessians() {
  return window_coordinates<P>() <= 32;
}

// Gradient and Hessian of L~(a_index) in its coordinates; index -1 until computed.
template <class P>
struct WindowHessian {
  static constexpr int size = window_coordinates<P>();
  Vec<double, size> gradient;
  Eigen::Matrix<double, size, size> hessian;
  long index = -1;
};

// exp(δ) at δ = 0 with δ's d coordinates seeded in TD (Dual<double, d> or Hess<d>): constants
// of the group, computed once (its series in TD cost ~10% of a beanie step when taken per window).
template <class G, class TD>
const typename G::template Element<TD>& exp_of_seeded_zero() {
  static const typename G::template Element<TD> e = [] {
    typename G::template Tangent<TD> delta;
    for (int c = 0; c < G::dim; ++c) delta(c) = TD::variable(0.0, c);
    return G::template exp<TD>(delta);
  }();
  return e;
}

// L_d and χ_d in Hess<nw - m> arithmetic (the window's nodes and increments); L~ = L_d + λ·χ_d is
// linear in λ, so its λ rows are χ_d's gradient and its λλ block is zero. The reference for
// window_hessian_taped, and the route for groups without element scalars.
template <class P>
void window_hessian_forward(const P& problem, const Window<P, double>& a, const Vec<double, P::num_constraints>& lam, double h,
                    WindowHessian<P>& out) {
  using G = typename P::Group;
  constexpr int k = P::order, r = P::shape_dim, d = G::dim, m = P::num_constraints, nw = window_coordinates<P>();
  constexpr int nx = nw - m;
  using T = Hess<nx>;
  // A's scalars start at zero (Hess()): the variables and the increments' scalars are written in
  // place, not built as temporaries of 440 bytes (Hess<9>) and copied.
  Window<P, T> A;
  int w = 0;
  for (int i = 0; i <= k; ++i)
    for (int c = 0; c < r; ++c, ++w) make_variable_in_place(A.p[i](c), a.p[i](c), w);
  A.p_low = a.p_low;
  for (int i = 0; i < k; ++i, w += d) {
    if constexpr (has_element_scalars<G>()) {
      // g~ exp(δ) depends on δ alone: computed in Hess<d>, placed in its d directions.
      using TD = Hess<d>;
      auto moved = G::compose(G::template cast<TD>(a.g[i]), exp_of_seeded_zero<G, TD>());
      const auto from = ElementScalars<G>::of(moved);
      const auto to = ElementScalars<G>::of(A.g[i]);
      for (int c = 0; c < ElementScalars<G>::count; ++c) add_embedded(*to[c], *from[c], w);
    } else {
      typename G::template Tangent<T> delta;
      for (int c = 0; c < d; ++c) delta(c) = T::variable(0.0, w + c);
      A.g[i] = G::compose(G::template cast<T>(a.g[i]), G::template exp<T>(delta));
    }
  }
  // L~ = L_d + Σ λ_c χ_c accumulated in one Hess (contiguous), then unpacked once.
  T L = problem.template lagrangian<T>(A, h);
  if constexpr (m > 0) {
    const Vec<T, m> chi = problem.template constraints<T>(A, h);
    for (int c = 0; c < m; ++c) {
      add_scaled(L, lam(c), chi(c));
      out.gradient(nx + c) = chi(c).v;
      for (int i = 0; i < nx; ++i) out.hessian(i, nx + c) = out.hessian(nx + c, i) = chi(c).g[i];
    }
    out.hessian.template bottomRightCorner<m, m>().setZero();
  }
  unpack_derivatives(L, out.gradient, out.hessian);
}

// The same derivatives by reverse over forward (taped_hessian.hpp): L_d and χ_d run once in
// first-order arithmetic on a tape, and one reverse sweep with the weights (1, λ) gives ∇²L~ in the
// nodes and increments. The increments' scalars u = g~ exp(δ) are computed in Hess<d> (they
// depend on δ alone) and enter the tape as sources with their gradients; their own curvature
// adds ū ∇²u, ū their adjoints. Equal to window_hessian_forward to rounding (tests).
template <class P>
void window_hessian_taped(const P& problem, const Window<P, double>& a, const Vec<double, P::num_constraints>& lam,
                          double h, WindowHessian<P>& out) {
  using G = typename P::Group;
  constexpr int k = P::order, r = P::shape_dim, d = G::dim, m = P::num_constraints, nw = window_coordinates<P>();
  constexpr int nx = nw - m, s = ElementScalars<G>::count;
  using T = Taped<nx>;
  using TD = Hess<d>;
  thread_local Tape<nx> tape;  // reused: its buffers grow once per thread
  tape.clear();
  Window<P, T> A;
  int w = 0;
  for (int i = 0; i <= k; ++i)
    for (int c = 0; c < r; ++c, ++w) A.p[i](c) = tape.variable(a.p[i](c), w);
  A.p_low = a.p_low;
  std::array<std::array<TD, s>, k> increment_scalars;
  for (int i = 0; i < k; ++i, w += d) {
    auto moved = G::compose(G::template cast<TD>(a.g[i]), exp_of_seeded_zero<G, TD>());
    const auto from = ElementScalars<G>::of(moved);
    const auto to = ElementScalars<G>::of(A.g[i]);
    for (int c = 0; c < s; ++c) {
      Eigen::Matrix<double, nx, 1> g = Eigen::Matrix<double, nx, 1>::Zero();
      for (int b = 0; b < d; ++b) g(w + b) = from[c]->g[b];
      *to[c] = tape.source(from[c]->v, g);
      increment_scalars[i][c] = *from[c];
    }
  }
  const T L = problem.template lagrangian<T>(A, h);
  Eigen::Matrix<double, nx, 1> gradient = tape.gradient(L);
  tape.seed(L, 1.0);
  if constexpr (m > 0) {
    const Vec<T, m> chi = problem.template constraints<T>(A, h);
    for (int c = 0; c < m; ++c) {
      const Eigen::Matrix<double, nx, 1> gc = tape.gradient(chi(c));
      gradient += lam(c) * gc;
      tape.seed(chi(c), lam(c));
      out.gradient(nx + c) = chi(c).v;
      for (int i = 0; i < nx; ++i) out.hessian(i, nx + c) = out.hessian(nx + c, i) = gc(i);
    }
    out.hessian.template bottomRightCorner<m, m>().setZero();
  }
  Eigen::Matrix<double, nx, nx> H = Eigen::Matrix<double, nx, nx>::Zero();
  tape.sweep(H);
  w = (k + 1) * r;
  for (int i = 0; i < k; ++i, w += d) {
    const auto to = ElementScalars<G>::of(A.g[i]);
    for (int c = 0; c < s; ++c) {
      const double u = tape.adjoint(*to[c]);
      if (u == 0.0) continue;
      for (int p = 0; p < d; ++p)
        for (int q = 0; q < d; ++q) H(w + p, w + q) += u * increment_scalars[i][c].hessian(p, q);
    }
  }
  out.gradient.template head<nx>() = gradient;
  out.hessian.template topLeftCorner<nx, nx>() = H;
}

// L~(a)'s gradient and Hessian (WindowHessian): by the tape where the group's elements are
// stored as scalars, otherwise in Hess arithmetic.
template <class P>
void window_hessian(const P& problem, const Window<P, double>& a, const Vec<double, P::num_constraints>& lam, double h,
                    WindowHessian<P>& out) {
  if constexpr (has_element_scalars<typename P::Group>())
    window_hessian_taped(problem, a, lam, h, out);
  else
    window_hessian_forward(problem, a, lam, h, out);
}

// The gradient alone of L~(a) in the window's coordinates, in first-order duals (the λ entries
// are χ_d). With the increments' perturbations B, a step's residual is Σ Bᵀ g over its windows
// (the file comment); for window a_n this costs one pass in Dual<nw - m> over the user's L_d
// and χ_d, where the perturbed window (node_residual) carries node n's moves through group
// operations (beanie control: compose, exp and the connection in Dual<4>, ~2x the pass).
template <class P>
Vec<double, window_coordinates<P>()> window_gradient(const P& problem, const Window<P, double>& a,
                                                     const Vec<double, P::num_constraints>& lam, double h) {
  using G = typename P::Group;
  constexpr int k = P::order, r = P::shape_dim, d = G::dim, m = P::num_constraints, nw = window_coordinates<P>();
  constexpr int nx = nw - m;
  using T = Dual<double, nx>;
  Window<P, T> A;
  int w = 0;
  for (int i = 0; i <= k; ++i)
    for (int c = 0; c < r; ++c) A.p[i](c) = T::variable(a.p[i](c), w++);
  A.p_low = a.p_low;
  for (int i = 0; i < k; ++i, w += d) {
    if constexpr (has_element_scalars<G>()) {
      // g~ exp(δ) depends on δ alone: computed in Dual<d>, placed in its d directions.
      using TD = Dual<double, d>;
      auto moved = G::compose(G::template cast<TD>(a.g[i]), exp_of_seeded_zero<G, TD>());
      const auto from = ElementScalars<G>::of(moved);
      const auto to = ElementScalars<G>::of(A.g[i]);
      for (int c = 0; c < ElementScalars<G>::count; ++c) {
        to[c]->v = from[c]->v;
        to[c]->d.fill(0.0);
        for (int b = 0; b < d; ++b) to[c]->d[w + b] = from[c]->d[b];
      }
    } else {
      typename G::template Tangent<T> delta;
      for (int c = 0; c < d; ++c) delta(c) = T::variable(0.0, w + c);
      A.g[i] = G::compose(G::template cast<T>(a.g[i]), G::template exp<T>(delta));
    }
  }
  T L = problem.template lagrangian<T>(A, h);
  Vec<double, nw> out;
  if constexpr (m > 0) {
    const Vec<T, m> chi = problem.template constraints<T>(A, h);
    for (int c = 0; c < m; ++c) {
      L = L + lam(c) * chi(c);
      out(nx + c) = chi(c).v;
    }
  }
  for (int i = 0; i < nx; ++i) out(i) = L.d[i];
  return out;
}

// An increment g~ over (p0, p1) perturbed by a move ε = (δp, η) of its right end (node_at_right)
// or left end, as y = log(g~^{-1} g~') in ε and in its own coordinates x = (δp0, δp1, δ):
// B = ∂y/∂ε and C[q] = ∂²y_q/∂ε∂x at 0.
template <class P>
struct IncrementPerturbation {
  static constexpr int r = P::shape_dim, d = P::Group::dim, node = r + d, own = 2 * r + d;
  Eigen::Matrix<double, d, node> B;
  std::array<Eigen::Matrix<double, node, own>, d> C;
};

// What a flow carries from step to step: the last k + 1 windows' Hessians (window a_i in slot
// i mod (k + 1)), and step n's increment perturbations, computed by solve_step for its fixed part
// and reused by step_sensitivity (both state-only: increment n-1, and n when k >= 2).
template <class P>
struct WindowHessianCarry {
  std::array<WindowHessian<P>, P::order + 1> slot;
  WindowHessian<P>& of(long index) { return slot[static_cast<size_t>(index % (P::order + 1))]; }
  bool holds(long first, long last) {
    for (long i = first; i <= last; ++i)
      if (of(i).index != i) return false;
    return true;
  }
  IncrementPerturbation<P> left, right;
  long left_step = -1, right_step = -1;
};

// The group's structure constants as matrices: ad[b] w = [e_b, w] = d/dt Ad_{exp(t e_b)} w at 0.
template <class G>
const std::array<Eigen::Matrix<double, G::dim, G::dim>, G::dim>& lie_brackets() {
  static const auto ad = [] {
    constexpr int d = G::dim;
    using T1 = Dual<double, 1>;
    std::array<Eigen::Matrix<double, d, d>, d> out;
    for (int b = 0; b < d; ++b) {
      typename G::template Tangent<T1> t = G::template Tangent<T1>::Constant(T1(0.0));
      t(b) = T1::variable(0.0, 0);
      const Eigen::Matrix<T1, d, d> Ad = G::Ad(G::template exp<T1>(t));
      for (int i = 0; i < d; ++i)
        for (int j = 0; j < d; ++j) out[b](i, j) = Ad(i, j).d[0];
    }
    return out;
  }();
  return ad;
}

// B and C to first order in ε (local_action.hpp's perturbation, A = A(p0 + δp0, p1 + δp1)):
//   right end: g~' = g~ exp(δ) A^{-1} exp(η) A(p0, p1 + δp)  =>  y = log(exp(δ) exp(v)),
//              v = Ad_{A^{-1}} η + R δp;
//   left end:  g~' = exp(-η) g~ exp(δ) A^{-1} A(p0 + δp, p1)  =>  y = log(exp(-u) exp(δ) exp(v)),
//              u = Ad_{g~^{-1}} η, v = R δp;
// R the moved end's right-trivialized connection derivative, R δp = log(A^{-1} A(.., end + δp)).
// By Baker–Campbell–Hausdorff, y = δ + v − u + ½ [δ, v] + ½ [δ, u] + O(ε², δ² ε), so
// B = ∂(v − u)/∂ε, C in δ is ½ [e_b, ∂(v ± u)/∂ε], and C in the ends is ∂²v/∂ε∂(δp0, δp1):
// R's and Ad_{A^{-1}}'s first derivatives in the ends (a nested dual over the connection only).
template <class P>
IncrementPerturbation<P> increment_perturbation(const P& problem, const Vec<double, P::shape_dim>& p0,
                                                const Vec<double, P::shape_dim>& p1, const GroupElement<P, double>& g,
                                                bool node_at_right) {
  using G = typename P::Group;
  using IP = IncrementPerturbation<P>;
  constexpr int r = IP::r, d = IP::d, node = IP::node;
  using TX = Dual<double, 2 * r>;  // the ends' δp0, δp1
  Eigen::Matrix<TX, d, r> R;
  Eigen::Matrix<TX, d, d> ad_inverse;  // Ad_{A^{-1}}
  R.setConstant(TX(0.0));
  ad_inverse.setConstant(TX(0.0));
  for (int q = 0; q < d; ++q) ad_inverse(q, q) = TX(1.0);
  if constexpr (has_connection<P>()) {
    using TP = Dual<TX, r>;  // and the moved end's δp
    Vec<TX, r> x0, x1;
    Vec<TP, r> q0, q1, dp;
    for (int c = 0; c < r; ++c) {
      x0(c) = TX::variable(p0(c), c);
      x1(c) = TX::variable(p1(c), r + c);
      q0(c) = TP(x0(c));
      q1(c) = TP(x1(c));
      dp(c) = TP::variable(TX(0.0), c);
    }
    const GroupElement<P, TP> moved = node_at_right ? connection(problem, q0, Vec<TP, r>(q1 + dp))
                                                    : connection(problem, Vec<TP, r>(q0 + dp), q1);
    const typename G::template Tangent<TP> rel = G::log(G::compose(G::inverse(connection(problem, q0, q1)), moved));
    for (int q = 0; q < d; ++q)
      for (int c = 0; c < r; ++c) R(q, c) = rel(q).d[c];
    if (node_at_right) ad_inverse = G::Ad(G::inverse(connection(problem, x0, x1)));
  }
  IP out;
  for (auto& Cq : out.C) Cq.setZero();
  for (int q = 0; q < d; ++q) {
    for (int c = 0; c < r; ++c) {
      out.B(q, c) = R(q, c).v;
      for (int b = 0; b < 2 * r; ++b) out.C[q](c, b) = R(q, c).d[b];
    }
    for (int a = 0; a < d; ++a) {
      if (node_at_right) {
        out.B(q, r + a) = ad_inverse(q, a).v;
        for (int b = 0; b < 2 * r; ++b) out.C[q](r + a, b) = ad_inverse(q, a).d[b];
      }
    }
  }
  Eigen::Matrix<double, d, d> sign = Eigen::Matrix<double, d, d>::Identity();
  if (!node_at_right) {  // -u = -Ad_{g~^{-1}} η, and its bracket term has the opposite sign
    out.B.template rightCols<d>() = -G::Ad(G::inverse(g));
    sign = -sign;
  }
  const auto& ad = lie_brackets<G>();
  for (int b = 0; b < d; ++b) {
    Eigen::Matrix<double, d, node> bracket = 0.5 * ad[b] * out.B;
    bracket.template rightCols<d>() = bracket.template rightCols<d>() * sign;
    for (int q = 0; q < d; ++q) out.C[q].col(2 * r + b) = bracket.row(q).transpose();
  }
  return out;
}

// The perturbations of the block's two increments next to its node c = k (increment c-1 has
// the node at its right, increment c at its left), from the carry when computed there for step
// n, else computed (and kept when they depend on the state alone).
template <class P>
const IncrementPerturbation<P>& step_increment_perturbation(const P& problem, const NodeBlock<P, double>& b,
                                                            WindowHessianCarry<P>& carry, long n, bool right) {
  constexpr int c = P::order;
  IncrementPerturbation<P>& ip = right ? carry.right : carry.left;
  long& at = right ? carry.right_step : carry.left_step;
  const bool state_only = !right || P::order >= 2;  // for k = 1, increment c = 2k - 1 is the unknown
  if (!(state_only && at == n)) {
    if constexpr (P::Group::dim > 0)
      ip = right ? increment_perturbation(problem, b.p[c], b.p[c + 1], b.g[c], false)
                 : increment_perturbation(problem, b.p[c - 1], b.p[c], b.g[c - 1], true);
    at = state_only ? n : -1;
  }
  return ip;
}

// E_c's part from windows c-k+first .. c-k+last (c = k, the step's node): Σ_j Bᵀ g_j (the file
// comment), from the windows' gradients (gradient_of(j)).
template <class P, class GradientOf>
Vec<double, Dims<P>::node> node_gradient_from_windows(GradientOf&& gradient_of, int first, int last,
                                                      const IncrementPerturbation<P>& left,
                                                      const IncrementPerturbation<P>& right) {
  constexpr int k = P::order, r = P::shape_dim, d = P::Group::dim, c = k;
  Vec<double, Dims<P>::node> E = Vec<double, Dims<P>::node>::Zero();
  for (int j = first; j <= last; ++j) {
    const Vec<double, window_coordinates<P>()>& g = gradient_of(j);
    E.template head<r>() += g.template segment<r>((c - j) * r);
    if constexpr (d > 0) {
      if (j <= c - 1) E.noalias() += left.B.transpose() * g.template segment<d>((k + 1) * r + (c - 1 - j) * d);
      if (j >= 1) E.noalias() += right.B.transpose() * g.template segment<d>((k + 1) * r + (c - j) * d);
    }
  }
  return E;
}

// ∂E_c/∂x for node c = k of the block from windows first .. k, and, if with_constraints, ∂χ_d/∂x
// of window k's in rows node..; columns placed by column(j, w) (window j's coordinate w; negative:
// not wanted). Each window's Hessian comes from hessian_of(j); left and right as
// step_increment_perturbation's.
template <class P, int Rows, int Cols, class HessianOf, class Column>
void node_derivatives_from_windows(HessianOf&& hessian_of, const IncrementPerturbation<P>& left,
                                   const IncrementPerturbation<P>& right, Column&& column, bool with_constraints,
                                   Eigen::Matrix<double, Rows, Cols>& J, int first = 0) {
  constexpr int k = P::order, r = P::shape_dim, d = P::Group::dim, m = P::num_constraints, node = r + d;
  constexpr int nw = window_coordinates<P>(), c = k;
  using IP = IncrementPerturbation<P>;
  for (int j = first; j <= k; ++j) {
    const WindowHessian<P>& wh = hessian_of(j);
    const auto& H = wh.hessian;
    Eigen::Matrix<double, node, nw> dE = Eigen::Matrix<double, node, nw>::Zero();
    dE.template topRows<r>() = H.template middleRows<r>((c - j) * r);  // node c's δp moves p only
    if constexpr (d > 0) {
      // Increment q of window j (its nodes q and q+1) moved by ε, with perturbation ip.
      auto add_increment = [&](const IP& ip, int q) {
        const int off = (k + 1) * r + q * d;
        dE.noalias() += ip.B.transpose() * H.template middleRows<d>(off);
        for (int a = 0; a < d; ++a) {
          const double ga = wh.gradient(off + a);
          dE.template middleCols<r>(q * r) += ga * ip.C[a].template leftCols<r>();
          dE.template middleCols<r>((q + 1) * r) += ga * ip.C[a].template middleCols<r>(r);
          dE.template middleCols<d>(off) += ga * ip.C[a].template rightCols<d>();
        }
      };
      if (j <= c - 1) add_increment(left, c - 1 - j);
      if (j >= 1) add_increment(right, c - j);
    }
    for (int w = 0; w < nw; ++w) {
      const int col = column(j, w);
      if (col < 0) continue;
      for (int i = 0; i < node; ++i) J(i, col) += dE(i, w);
      if constexpr (m > 0) {
        if (with_constraints && j == k)
          for (int i = 0; i < m; ++i) J(node + i, col) += H(nw - m + i, w);
      }
    }
  }
}

}  // namespace lpshoot
