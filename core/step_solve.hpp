// Solving one step of the discrete flow map (step.hpp's equations, METHOD.md §3): the
// predictor, Newton (newton.hpp) with chord steps on a carried matrix, the confirmation of a
// step ended on a predicted chord end, and the step's sensitivity by the implicit function
// theorem: dz = -(∂F/∂z)^{-1} (∂F/∂state) d(state).
#pragma once

#include "newton.hpp"
#include "step.hpp"

#include <string>

namespace lpshoot {

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
    fixed = node_gradient_from_windows<P>([&](int j) -> const auto& { return carry->of(n - k + j).gradient; }, 0,
                                          k - 1, step_increment_perturbation(problem, b, *carry, n, false),
                                          step_increment_perturbation(problem, b, *carry, n, true));
  } else {
    fixed = step_fixed_part(problem, h, s, z);
  }
  if (!all_finite(fixed.data(), D::node)) return non_finite_step(StepReport(), n);
  // In a flow with sensitivities (a carry) with a group (k >= 2), F from window a_n's gradient and
  // increment n's perturbation, which depends on the state alone (step_residual_from_window):
  // beanie control, ~half a residual; such a flow's steps end on confirmations from the windows'
  // gradients anyway. Without, F from the perturbed windows, whose rounding is that of the
  // discrete momentum map: the beanie control's flow with multipliers kept its momentum to
  // 2.9e-12 and 4.9e-12 relative over 600 steps, 1.0e-11 and 1.3e-11 with F from the gradient
  // (tests/test_momentum.cpp, both constraint sets).
  constexpr bool gradient_residual_possible = uses_window_hessians<P>() && D::d > 0 && k >= 2;
  const IncrementPerturbation<P>* right = nullptr;
  if constexpr (gradient_residual_possible) {
    if (carry) right = &step_increment_perturbation(problem, step_block<P, double>(s, z, false), *carry, n, true);
  }
  auto newton = [&] {
    return newton_solve<nz>(
        n, opt,
        [&](Vec<double, nz>& F, Eigen::Matrix<double, nz, nz>& J) {
          // With a group, window a_n's Hessian: nested duals would carry the z directions through
          // the perturbed increments' group operations (beanie control: 1.5x the step). Without
          // one, nested duals in the nz directions of z alone cost less than the window's
          // whole Hessian (electron: 3 directions against Hess<9>).
          if constexpr (uses_window_hessians<P>() && D::d > 0)
            step_matrix_from_window(problem, h, s, z, fixed, F, J);
          else
            evaluate_step<P, nz>(problem, h, s, z, false, &fixed, F, J);
        },
        [&](Vec<double, nz>& F) {
          if constexpr (gradient_residual_possible) {
            if (right) {
              F = step_residual_from_window(problem, h, s, z, fixed, *right);
              return;
            }
          }
          F = step_residual(problem, h, s, z, fixed);
        },
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
      [&](int j) -> const auto& { return carry.of(n - k + j).gradient; }, 0, k,
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
  return implicit_sensitivity<nz, ns>(J, chord, condition);
}

}  // namespace lpshoot
