// One step of the discrete flow map (METHOD.md §3, paper Propositions 1–2): the step's
// equations and their derivatives. Solving them, and the step's sensitivity: step_solve.hpp.
//
// Step n (n >= k) solves F(z) = (E_n, chi_d(a_n)) = 0 for z = (p_{n+k}, ζ, λ^n), where
// g~_{n+k-1} = ĝ exp(ζ) around the current iterate ĝ (re-centred after every update, so the
// derivatives are always taken at ζ = 0). ∂F/∂z is the matrix of Proposition 2; its condition
// number is the regularity diagnostic.
#pragma once

#include "local_action.hpp"
#include "step_window_hessian.hpp"

#include <stdexcept>

namespace lpshoot {

// The data one step needs: nodes n-k .. n+k-1, increments g~_{n-k} .. g~_{n+k-2} and
// multipliers λ^{n-k} .. λ^{n-1}. Before the first step (n = k) it is the flow's initial data
// p_0 .. p_{2k-1}, g~_0 .. g~_{2k-2}, λ^0 .. λ^{k-1}. Its tangent coordinates (size
// Dims<P>::state) are δp for each node, δ with g~ -> g~ exp(δ) for each increment, δλ.
template <class P>
struct FlowState {
  static constexpr int k = P::order;
  std::array<Vec<double, P::shape_dim>, 2 * k> p;
  std::array<GroupElement<P, double>, 2 * k - 1> g;
  std::array<Vec<double, P::num_constraints>, k> lam;
  // Low parts of the nodes (compensated.hpp): node i is p[i] + p_low[i]; zero unless the problem
  // keeps them. Tangent coordinates move the sum.
  std::array<Vec<double, P::shape_dim>, 2 * k> p_low = zero_nodes<P::shape_dim, 2 * k>();

  static constexpr int p_offset(int i) { return i * P::shape_dim; }
  static constexpr int g_offset(int i) { return 2 * k * P::shape_dim + i * P::Group::dim; }
  static constexpr int lam_offset(int j) {
    return 2 * k * P::shape_dim + (2 * k - 1) * P::Group::dim + j * P::num_constraints;
  }
};

// What one step solves for.
template <class P>
struct StepUnknowns {
  Vec<double, P::shape_dim> p;      // p_{n+k}
  Vec<double, P::shape_dim> p_low = Vec<double, P::shape_dim>::Zero();  // its low part (FlowState)
  GroupElement<P, double> g;        // g~_{n+k-1}
  Vec<double, P::num_constraints> lam;  // λ^n
};

// The step's node block (nodes n-k .. n+k) in scalar T. With T a Dual, the unknowns z are seeded
// in derivative columns 0..nz-1 and, if seed_state, the state's tangent coordinates after them.
template <class P, class T>
NodeBlock<P, T> step_block(const FlowState<P>& s, const StepUnknowns<P>& z, bool seed_state) {
  using D = Dims<P>;
  using G = typename P::Group;
  using FS = FlowState<P>;
  constexpr int k = D::k, nz = D::unknowns;
  auto var = [](double x, int col) {
    if constexpr (std::is_same_v<T, double>) {
      (void)col;
      return x;
    } else {
      return col < static_cast<int>(T().d.size()) ? T::variable(x, col) : T(x);
    }
  };
  if constexpr (!std::is_same_v<T, double>) {
    if (seed_state && static_cast<int>(T().d.size()) < nz + D::state)
      throw std::logic_error("step_block: state seeds need nz + state derivative columns");
  }
  NodeBlock<P, T> b;
  for (int i = 0; i < 2 * k; ++i)
    for (int a = 0; a < D::r; ++a) b.p[i](a) = seed_state ? var(s.p[i](a), nz + FS::p_offset(i) + a) : T(s.p[i](a));
  for (int a = 0; a < D::r; ++a) b.p[2 * k](a) = var(z.p(a), a);
  for (int i = 0; i < 2 * k; ++i) b.p_low[i] = s.p_low[i];
  b.p_low[2 * k] = z.p_low;
  for (int i = 0; i < 2 * k - 1; ++i) {
    b.g[i] = G::template cast<T>(s.g[i]);
    if (seed_state) {
      typename G::template Tangent<T> delta;
      for (int a = 0; a < D::d; ++a) delta(a) = var(0.0, nz + FS::g_offset(i) + a);
      b.g[i] = G::compose(b.g[i], G::template exp<T>(delta));
    }
  }
  b.g[2 * k - 1] = G::template cast<T>(z.g);
  if constexpr (!std::is_same_v<T, double>) {  // g~_{n+k-1} = ĝ exp(ζ), ζ = 0 seeded
    typename G::template Tangent<T> zeta;
    for (int a = 0; a < D::d; ++a) zeta(a) = var(0.0, D::r + a);
    b.g[2 * k - 1] = G::compose(b.g[2 * k - 1], G::template exp<T>(zeta));
  }
  for (int j = 0; j < k; ++j)
    for (int a = 0; a < D::m; ++a)
      b.lam[j](a) = seed_state ? var(s.lam[j](a), nz + FS::lam_offset(j) + a) : T(s.lam[j](a));
  for (int a = 0; a < D::m; ++a) b.lam[k](a) = var(z.lam(a), D::r + D::d + a);
  return b;
}

// The part of E_n that does not depend on z: windows a_{n-k} .. a_{n-1} (z = (p_{n+k}, g~_{n+k-1},
// λ^n) enters window a_n only). Computed once per step.
template <class P>
Vec<double, Dims<P>::node> step_fixed_part(const P& problem, double h, const FlowState<P>& s,
                                           const StepUnknowns<P>& z) {
  const NodeBlock<P, double> b = step_block<P, double>(s, z, false);
  return node_residual(problem, b, P::order, 0, P::order - 1, h);
}

// F = (E_n, chi_d(a_n)) at z, values only, given the fixed part of E_n.
template <class P>
Vec<double, Dims<P>::unknowns> step_residual(const P& problem, double h, const FlowState<P>& s,
                                             const StepUnknowns<P>& z, const Vec<double, Dims<P>::node>& fixed) {
  using D = Dims<P>;
  const NodeBlock<P, double> b = step_block<P, double>(s, z, false);
  Vec<double, D::unknowns> F;
  F.template head<D::node>() = fixed + node_residual(problem, b, D::k, D::k, D::k, h);
  if constexpr (D::m > 0) F.template tail<D::m>() = problem.template constraints<double>(b.window(D::k), h);
  return F;
}

// F and its derivatives at (state, z). Derivative columns: the nz unknowns, then (if with_state)
// the state's tangent coordinates. Given `fixed` (and no state derivatives), only window a_n is
// differentiated.
template <class P, int NO>
void evaluate_step(const P& problem, double h, const FlowState<P>& s, const StepUnknowns<P>& z, bool with_state,
                   const Vec<double, Dims<P>::node>* fixed, Vec<double, Dims<P>::unknowns>& F,
                   Eigen::Matrix<double, Dims<P>::unknowns, NO>& J) {
  using D = Dims<P>;
  using T = Dual<double, NO>;
  constexpr int k = D::k, nz = D::unknowns;
  const NodeBlock<P, T> b = step_block<P, T>(s, z, with_state);
  Vec<T, nz> Fd;
  Fd.template head<D::node>() = node_residual(problem, b, k, fixed ? k : 0, k, h);
  if constexpr (D::m > 0) Fd.template tail<D::m>() = problem.template constraints<T>(b.window(k), h);
  for (int i = 0; i < nz; ++i) {
    F(i) = Fd(i).v + (fixed && i < D::node ? (*fixed)(i) : 0.0);
    for (int c = 0; c < NO; ++c) J(i, c) = Fd(i).d[c];
  }
}

// Window j's coordinate w (nodes, increments, λ: window_coordinates) -> its column in the step's
// (z, state) matrix: the unknowns first, then the state's tangent coordinates (FlowState).
template <class P>
int step_column(int j, int w) {
  using D = Dims<P>;
  using FS = FlowState<P>;
  constexpr int k = D::k, r = D::r, d = D::d, nz = D::unknowns;
  if (w < (k + 1) * r) {
    const int i = j + w / r, a = w % r;
    return i < 2 * k ? nz + FS::p_offset(i) + a : a;
  }
  w -= (k + 1) * r;
  if (w < k * d) {
    const int i = j + w / d, a = w % d;
    return i < 2 * k - 1 ? nz + FS::g_offset(i) + a : r + a;
  }
  w -= k * d;
  return j < k ? nz + FS::lam_offset(j) + w : r + d + w;
}

// F and its derivatives in the unknowns and the state's tangent coordinates (nz + state columns),
// one window at a time: E_n = Σ_j ∂L~(a_j)/∂(node n) over windows j = n-k .. n, and window a_j
// depends only on its own nodes, increments and λ^j ((k+1) r + k d + m coordinates, issue 9).
// Each window is differentiated in those directions only and its columns are placed in J. Same
// numbers as evaluate_step with with_state, to roundoff; the reference for the window Hessians'
// path (step_window_hessian.hpp), and the path for windows too wide for it.
template <class P>
void evaluate_step_by_window(const P& problem, double h, const FlowState<P>& s, const StepUnknowns<P>& z,
                             Vec<double, Dims<P>::unknowns>& F,
                             Eigen::Matrix<double, Dims<P>::unknowns, Dims<P>::unknowns + Dims<P>::state>& J) {
  using D = Dims<P>;
  using G = typename P::Group;
  constexpr int k = D::k, r = D::r, d = D::d, m = D::m, nz = D::unknowns;
  constexpr int nw = window_coordinates<P>();
  using T = Dual<double, nw>;
  const NodeBlock<P, double> b0 = step_block<P, double>(s, z, false);
  F.setZero();
  J.setZero();
  for (int j = 0; j <= k; ++j) {
    NodeBlock<P, T> b = lift<T>(b0);
    int w = 0;
    for (int i = j; i <= j + k; ++i)
      for (int a = 0; a < r; ++a, ++w) b.p[i](a) = T::variable(b0.p[i](a), w);
    for (int i = j; i < j + k; ++i) {
      typename G::template Tangent<T> delta;
      for (int a = 0; a < d; ++a, ++w) delta(a) = T::variable(0.0, w);
      b.g[i] = G::compose(b.g[i], G::template exp<T>(delta));
    }
    for (int a = 0; a < m; ++a, ++w) b.lam[j](a) = T::variable(b0.lam[j](a), w);
    Vec<T, nz> Fj;
    Fj.template head<D::node>() = node_residual(problem, b, k, j, j, h);
    if constexpr (m > 0) {
      if (j == k) Fj.template tail<m>() = problem.template constraints<T>(b.window(k), h);
      else Fj.template tail<m>().setConstant(T(0.0));
    }
    for (int i = 0; i < nz; ++i) {
      F(i) += Fj(i).v;
      for (int c = 0; c < nw; ++c) J(i, step_column<P>(j, c)) += Fj(i).d[c];
    }
  }
}

// ∂F/∂(z, state) from the windows' Hessians (step_window_hessian.hpp): window a_n's is computed
// here, a_{n-k} .. a_{n-1}'s are taken from `carry` when it holds them (a flow's consecutive
// steps: the same windows at the same points) and computed into it otherwise.
template <class P>
void step_jacobian_from_windows(const P& problem, double h, const FlowState<P>& s, const StepUnknowns<P>& z,
                                WindowHessianCarry<P>& carry, long n,
                                Eigen::Matrix<double, Dims<P>::unknowns, Dims<P>::unknowns + Dims<P>::state>& J) {
  constexpr int k = P::order;
  const NodeBlock<P, double> b0 = step_block<P, double>(s, z, false);
  for (int j = 0; j <= k; ++j) {
    const long index = n - k + j;
    WindowHessian<P>& wh = carry.of(index);
    if (j == k || wh.index != index) {
      window_hessian(problem, b0.window(j), b0.lam[j], h, wh);
      wh.index = index;
    }
  }
  const auto& left = step_increment_perturbation(problem, b0, carry, n, false);
  const auto& right = step_increment_perturbation(problem, b0, carry, n, true);
  J.setZero();
  node_derivatives_from_windows<P>([&](int j) -> const WindowHessian<P>& { return carry.of(n - k + j); }, left, right,
                                   step_column<P>, true, J);
}

// F at z from window a_n's gradient (window_gradient), given the fixed part of E_n: E_n =
// fixed + Bᵀ g over increment n's perturbation `right` (node n at its left end; it depends on the
// state alone for k >= 2), χ_d(a_n) from g's λ entries. step_residual's F, by the chain rule of
// step_window_hessian.hpp instead of node n's moves carried through the perturbed increments.
template <class P>
Vec<double, Dims<P>::unknowns> step_residual_from_window(const P& problem, double h, const FlowState<P>& s,
                                                         const StepUnknowns<P>& z,
                                                         const Vec<double, Dims<P>::node>& fixed,
                                                         const IncrementPerturbation<P>& right) {
  using D = Dims<P>;
  constexpr int k = D::k, m = D::m;
  const NodeBlock<P, double> b = step_block<P, double>(s, z, false);
  const auto g = window_gradient(problem, b.window(k), b.lam[k], h);
  Vec<double, D::unknowns> F;
  F.template head<D::node>() =
      fixed + node_gradient_from_windows<P>([&](int) -> const auto& { return g; }, k, k, right, right);
  if constexpr (m > 0) F.template tail<m>() = g.template tail<m>();
  return F;
}

// F and ∂F/∂z at z from window a_n's Hessian (the only window that contains z), given the fixed
// part of E_n: E_n's rows Σ Bᵀ g and Bᵀ H + Σ g C (step_window_hessian.hpp) over window a_n
// alone, χ_d(a_n) and its derivatives from the Hessian's λ rows. One pass in Hess arithmetic
// over the window instead of nested duals through the perturbed increments and the whole block
// (evaluate_step): a flow without sensitivities evaluates one per step (beanie control: ~60% of
// its step through nested duals).
template <class P>
void step_matrix_from_window(const P& problem, double h, const FlowState<P>& s, const StepUnknowns<P>& z,
                             const Vec<double, Dims<P>::node>& fixed, Vec<double, Dims<P>::unknowns>& F,
                             Eigen::Matrix<double, Dims<P>::unknowns, Dims<P>::unknowns>& Jz) {
  using D = Dims<P>;
  constexpr int k = D::k, m = D::m, nz = D::unknowns;
  const NodeBlock<P, double> b = step_block<P, double>(s, z, false);
  WindowHessian<P> wh;
  window_hessian(problem, b.window(k), b.lam[k], h, wh);
  IncrementPerturbation<P> right;  // increment n, its left end at node n (window a_n has no other)
  if constexpr (D::d > 0) right = increment_perturbation(problem, b.p[k], b.p[k + 1], b.g[k], false);
  auto window_n = [&](int) -> const WindowHessian<P>& { return wh; };
  Jz.setZero();
  node_derivatives_from_windows<P>(
      window_n, right, right, [](int j, int w) { const int col = step_column<P>(j, w); return col < nz ? col : -1; }, true,
      Jz, k);
  F.template head<D::node>() =
      fixed + node_gradient_from_windows<P>([&](int) -> const auto& { return wh.gradient; }, k, k, right, right);
  if constexpr (m > 0) F.template tail<m>() = wh.gradient.template tail<m>();
}

}  // namespace lpshoot
