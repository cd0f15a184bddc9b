// Hand-derived formulas for the paper's systems: independent oracles for the engine's derived
// equations, and the hand-written baselines of bench/bench_step.cpp.
#pragma once

#include <lpshoot/problems/beanie.hpp>
#include <lpshoot/problems/electron.hpp>

#include <array>

namespace lpshoot::oracles {

using problems::BeanieControl;
using problems::BeanieParameters;
using problems::Electron;

// METHOD.md §6.1, literally: D4 x - (right-hand side) for the three components at node n, from
// x_{n-2} .. x_{n+2}. Requires B = (0, 0, Bz).
Eigen::Vector3d electron_stencil_residual(const Electron& e, const std::array<Eigen::Vector3d, 5>& x, double h);

// Hand derivation of E_n = ∂/∂x_n of the three windows containing x_n:
//   E_n = (m/h)(U_{n-2} - 2U_{n-1} + U_n) + 2 potential h U_n + (e/c) B × (U_n - U_{n-1}).
Eigen::Vector3d electron_analytic_residual(const Electron& e, const std::array<Eigen::Vector3d, 5>& x, double h);

// The electron step, solved in closed form (E_n is linear in U_n): x_{n+2} from x_{n-2} .. x_{n+1}.
Eigen::Vector3d electron_analytic_step(const Electron& e, const std::array<Eigen::Vector3d, 4>& x, double h);

// The same step as a matrix, in closed form: x_{n+2} = Φ (x_{n-2}; x_{n-1}; x_n; x_{n+1}) (the step
// is linear and homogeneous in the nodes), and so also its sensitivity to the state. The
// hand-written paper electron flow of bench/bench_ratios.cpp forms it once per flow.
Eigen::Matrix<double, 3, 12> electron_paper_step_map(const Electron& e, double h);

// The k = 2 beanie optimal-control step solved by hand: the η-equations give λ^n in closed form,
// the ψ-equation gives u_n (hence ψ_{n+2}), the constraints give g~_{n+1}. See the .cpp.
StepUnknowns<BeanieControl> beanie_control_analytic_step(const BeanieControl& b,
                                                         const FlowState<BeanieControl>& s, double h);

// The same step with its sensitivity dz/d(state) written by hand: the tangent-linear form of each
// line of the closed form, in the engine's coordinates (step.hpp): rows (δψ_{n+2}, ζ with
// g~_{n+1} -> g~_{n+1} exp(ζ), δλ^n), columns the state's (δψ per node, δ with g~ -> g~ exp(δ) per
// increment, δλ). The oracle for step_sensitivity and the hand-written baseline of bench_step.
using BeanieStepSensitivity = Eigen::Matrix<double, Dims<BeanieControl>::unknowns, Dims<BeanieControl>::state>;
StepUnknowns<BeanieControl> beanie_control_analytic_step(const BeanieControl& b, const FlowState<BeanieControl>& s,
                                                         double h, BeanieStepSensitivity& sensitivity);

// The unreduced discrete Euler–Lagrange step of the free beanie, q = (x, y, θ, ψ), from the
// same L_d (METHOD.md §6.2) written in q: Δr and Δθ + cΔψ are conserved and
// μ (Δψ_n - Δψ_{n-1}) = -h^2 V'(ψ_n).
Eigen::Vector4d beanie_unreduced_step(const BeanieParameters& par, const Eigen::Vector4d& q_prev,
                                      const Eigen::Vector4d& q, double h);

}  // namespace lpshoot::oracles
