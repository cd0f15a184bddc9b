// One step of the discrete flow map (METHOD.md §3, paper Propositions 1–2).
//
// Step n (n >= k) solves F(z) = (E_n, chi_d(a_n)) = 0 for z = (p_{n+k}, ζ, λ^n), where
// g~_{n+k-1} = ĝ exp(ζ) around the current iterate ĝ (re-centred after every update, so the
// derivatives are always taken at ζ = 0). ∂F/∂z is the matrix of Proposition 2; its condition
// number is the regularity diagnostic. Sensitivities follow from the implicit function theorem:
// dz = -(∂F/∂z)^{-1} (∂F/∂state) d(state).
#pragma once

#include "local_action.hpp"
#include "newton.hpp"
#include "step_window_hessian.hpp"

#include <stdexcept>
#include <string>

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
  F.template head<D::node>() = fixed + node_gradient_from_windows<P>(window_n, k, k, right, right);
  if constexpr (m > 0) F.template tail<m>() = wh.gradient.template tail<m>();
}

template <class P>
void apply_correction(StepUnknowns<P>& z, const Vec<double, Dims<P>::unknowns>& dz) {
  using D = Dims<P>;
  using G = typename P::Group;
  if constexpr (keeps_low_parts<P>())
    add_compensated(z.p, z.p_low, Vec<double, D::r>(dz.template head<D::r>()));
  else
    z.p += dz.template head<D::r>();
  const typename G::template Tangent<double> dzeta = dz.template segment<D::d>(D::r);
  z.g = G::compose(z.g, G::template exp<double>(dzeta));
  z.lam += dz.template tail<D::m>();
}

// The predictor of step n's unknowns from the state. Plain: p_{n+k} by linear extrapolation
// (error O(h²)), g~_{n+k-1} = g~_{n+k-2} (O(h²) for increments of size O(h)), λ^n = λ^{n-1}
// (O(h)). Extrapolated (k >= 2, where the state holds three nodes, two increments and two
// multipliers back): p quadratically (O(h³)), g~ by g~₋₁ g~₋₂⁻¹ g~₋₁, linear in the group
// (O(h³)), λ linearly (O(h²)). A flow with sensitivities starts each step's chord steps on the
// previous step's matrix; they contract by a fixed ratio per step, so a closer start saves
// corrections (beanie control at h = 0.01: 3.6 residuals per step from the plain predictor).
template <class P>
void step_predictor(const FlowState<P>& s, bool extrapolated, StepUnknowns<P>& z) {
  using D = Dims<P>;
  using G = typename P::Group;
  constexpr int k = D::k;
  const int last = 2 * k - 1;
  if constexpr (keeps_low_parts<P>()) {
    const Vec<double, D::r> twice = 2.0 * s.p[last], twice_low = 2.0 * s.p_low[last];
    subtract_compensated(twice, twice_low, s.p[last - 1], s.p_low[last - 1], z.p, z.p_low);
  } else {
    z.p = 2.0 * s.p[last] - s.p[last - 1];
  }
  z.g = s.g[2 * k - 2];
  if constexpr (D::m > 0) z.lam = s.lam[k - 1];
  if constexpr (k >= 2) {
    if (!extrapolated) return;
    // The second difference, from the nodes' differences (and their low parts'), added on.
    Vec<double, D::r> second = (s.p[last] - s.p[last - 1]) - (s.p[last - 1] - s.p[last - 2]);
    if constexpr (keeps_low_parts<P>()) {
      second += (s.p_low[last] - s.p_low[last - 1]) - (s.p_low[last - 1] - s.p_low[last - 2]);
      add_compensated(z.p, z.p_low, second);
    } else {
      z.p += second;
    }
    z.g = G::compose(s.g[2 * k - 2], G::compose(G::inverse(s.g[2 * k - 3]), s.g[2 * k - 2]));
    if constexpr (D::m > 0) z.lam = 2.0 * s.lam[k - 1] - s.lam[k - 2];
  } else {
    (void)extrapolated;
  }
}

// |z_i| for Newton's convergence test: nodes and multipliers (0 for the group part).
template <class P>
Vec<double, Dims<P>::unknowns> step_magnitude(const StepUnknowns<P>& z) {
  using D = Dims<P>;
  Vec<double, D::unknowns> scale;
  scale.template head<D::r>() = z.p.cwiseAbs();
  scale.template segment<D::d>(D::r).setZero();
  scale.template tail<D::m>() = z.lam.cwiseAbs();
  return scale;
}

// Solves step n by Newton (newton.hpp) from the extrapolated predictor (step_predictor), and
// from the plain one if that fails (an extrapolation can overshoot where the solution is not
// resolved by the step: large h, a fast rotation), or from `start` when given. The
// z-independent windows are evaluated once per step, or, when `carry` holds their gradients (a
// flow with sensitivities), their part of E_n is Σ Bᵀ g (step_window_hessian.hpp). `chord`: a
// flow's factored step matrix, for chord iterations (newton_solve).
template <class P>
StepReport solve_step(const P& problem, double h, const FlowState<P>& s, int n, const NewtonOptions& opt,
                      StepUnknowns<P>& z, ChordMatrix<Dims<P>::unknowns>* chord = nullptr,
                      WindowHessianCarry<P>* carry = nullptr, const StepUnknowns<P>* start = nullptr) {
  using D = Dims<P>;
  constexpr int k = D::k, nz = D::unknowns;
  if (start)
    z = *start;
  else
    step_predictor(s, true, z);
  Vec<double, D::node> fixed;  // independent of z (window a_n alone contains it)
  if (carry && carry->holds(n - k, n - 1)) {
    const NodeBlock<P, double> b = step_block<P, double>(s, z, false);
    fixed = node_gradient_from_windows<P>([&](int j) -> const WindowHessian<P>& { return carry->of(n - k + j); }, 0,
                                          k - 1, step_increment_perturbation(problem, b, *carry, n, false),
                                          step_increment_perturbation(problem, b, *carry, n, true));
  } else {
    fixed = step_fixed_part(problem, h, s, z);
  }
  if (!all_finite(fixed.data(), D::node)) {
    StepReport rep;
    rep.step = n;
    rep.status = StepStatus::NonFinite;
    rep.message = "step n=" + std::to_string(n) + ": the step equations evaluated to a non-finite number";
    return rep;
  }
  auto newton = [&] {
    return newton_solve<nz>(
        n, opt,
        [&](Vec<double, nz>& F, Eigen::Matrix<double, nz, nz>& J) {
          if constexpr (uses_window_hessians<P>())
            step_matrix_from_window(problem, h, s, z, fixed, F, J);
          else
            evaluate_step<P, nz>(problem, h, s, z, false, &fixed, F, J);
        },
        [&](Vec<double, nz>& F) { F = step_residual(problem, h, s, z, fixed); },
        [&](const Vec<double, nz>& dz) { apply_correction(z, dz); },
        [&] { return step_magnitude(z); }, chord);
  };
  StepReport rep = newton();
  if (k >= 2 && !start && rep.status != StepStatus::Converged) {
    const int iterations = rep.iterations;
    step_predictor(s, false, z);
    rep = newton();
    rep.iterations += iterations;
  }
  return rep;
}

// Confirms a step that newton_solve ended on a prediction (StepReport::predicted), after its
// sensitivity evaluated window a_n at z (carry.of(n), step_jacobian_from_windows) and factored the
// exact step matrix there (`factored`): F at z is Σ_j Bᵀ g_j over the windows' gradients, and
// χ_d(a_n) (window a_n's λ gradient). The exact Newton correction must be within
// predicted_step_bound (newton.hpp); it is then applied (its error is O(correction²), below the
// chord step's that it replaces) and window a_n's carried gradient moved with it to first order:
// its Hessian times the correction in the window's coordinates and, for the increment re-centred
// at g~ exp(ζ), ½ (Σ_b ζ_b ad_b)ᵀ g_δ (Baker–Campbell–Hausdorff: g~ exp(ζ) exp(δ') =
// g~ exp(ζ + δ' + ½ [ζ, δ'] + ...)). The Hessian and the sensitivity stay those at z, off by the
// correction, relatively. False: nothing is changed and the caller solves again from z.
template <class P>
bool confirm_predicted_step(const P& problem, const NewtonOptions& opt, const FlowState<P>& s,
                            const ChordMatrix<Dims<P>::unknowns>& factored, WindowHessianCarry<P>& carry, long n,
                            StepUnknowns<P>& z) {
  using D = Dims<P>;
  using G = typename P::Group;
  constexpr int k = D::k, r = D::r, d = D::d, m = D::m, nz = D::unknowns, nw = window_coordinates<P>();
  const NodeBlock<P, double> b = step_block<P, double>(s, z, false);
  Vec<double, nz> F;
  F.template head<D::node>() = node_gradient_from_windows<P>(
      [&](int j) -> const WindowHessian<P>& { return carry.of(n - k + j); }, 0, k,
      step_increment_perturbation(problem, b, carry, n, false), step_increment_perturbation(problem, b, carry, n, true));
  WindowHessian<P>& wh = carry.of(n);
  if constexpr (m > 0) F.template tail<m>() = wh.gradient.template tail<m>();
  const Vec<double, nz> correction = factored.lu.solve(-F);
  const Vec<double, nz> scale = step_magnitude(z);
  if (!all_finite(correction.data(), nz) ||
      !((correction.cwiseAbs().array() - predicted_step_bound(opt, factored.condition) * (1.0 + scale.array())) <= 0.0)
           .all())
    return false;
  apply_correction(z, correction);
  // Window a_n's coordinates: nodes n .. n+k, increments n .. n+k-1, λ^n; z is the last node,
  // the last increment and λ^n.
  constexpr int zeta_at = (k + 1) * r + (k - 1) * d;
  Vec<double, nw> dx = Vec<double, nw>::Zero();
  dx.template segment<r>(k * r) = correction.template head<r>();
  if constexpr (d > 0) dx.template segment<d>(zeta_at) = correction.template segment<d>(r);
  if constexpr (m > 0) dx.template tail<m>() = correction.template tail<m>();
  Vec<double, nw> moved = wh.hessian * dx;
  if constexpr (d > 0) {
    const auto& ad = lie_brackets<G>();
    Eigen::Matrix<double, d, d> bracket = Eigen::Matrix<double, d, d>::Zero();
    for (int c = 0; c < d; ++c) bracket += correction(r + c) * ad[c];
    moved.template segment<d>(zeta_at) += 0.5 * (bracket.transpose() * wh.gradient.template segment<d>(zeta_at));
  }
  wh.gradient += moved;
  return true;
}

// dz/d(state) at a solved step n (nz x state), by the implicit function theorem. Optionally the
// step matrix ∂F/∂z there, factored (for the next step's chord iterations), and its 1-norm
// condition number (the regularity check at the solution). `carry`: the flow's window Hessians
// from its previous steps (step_jacobian_from_windows); without it every window is computed.
template <class P>
Eigen::Matrix<double, Dims<P>::unknowns, Dims<P>::state> step_sensitivity(
    const P& problem, double h, const FlowState<P>& s, const StepUnknowns<P>& z,
    ChordMatrix<Dims<P>::unknowns>* chord = nullptr, double* condition = nullptr,
    WindowHessianCarry<P>* carry = nullptr, long n = P::order) {
  using D = Dims<P>;
  constexpr int nz = D::unknowns, ns = D::state;
  Eigen::Matrix<double, nz, nz + ns> J;
  if constexpr (uses_window_hessians<P>()) {
    WindowHessianCarry<P> own;
    step_jacobian_from_windows(problem, h, s, z, carry ? *carry : own, n, J);
  } else {
    (void)carry, (void)n;
    Vec<double, nz> F;
    evaluate_step_by_window(problem, h, s, z, F, J);
  }
  const Eigen::Matrix<double, nz, nz> Jz = J.template leftCols<nz>();
  const Eigen::Matrix<double, nz, ns> Js = J.template rightCols<ns>();
  ChordMatrix<nz> own_chord;
  ChordMatrix<nz>& factored = chord ? *chord : own_chord;
  const Eigen::Matrix<double, nz, ns> dz = implicit_sensitivity<nz, ns>(Jz, Js, factored);
  if (condition) *condition = factored.condition;
  return dz;
}

}  // namespace lpshoot
