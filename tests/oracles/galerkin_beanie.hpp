// The beanie's Galerkin steps of orders 4 and 6 (METHOD.md §9 route (a): Hermite shape, group
// curve g_n exp(ξ) with ξ Hermite in se(2), quartic with one bubble each for order 6, the
// constraints at the Gauss points) derived by hand: the independent oracle for the engine's
// derived Galerkin steps on SE(2) and their sensitivities, and the hand-written baseline of
// bench/bench_ratios.cpp. The derivation is in the .cpp: se(2)'s translations as complex numbers
// make every group quantity a complex function of one angle.
#pragma once

#include <lpshoot/problems/beanie.hpp>

#include <Eigen/LU>

namespace lpshoot::oracles {

// Galerkin<BeanieModel, S>'s layout (galerkin.hpp): S = 3 (cubic, 2 Gauss points, order 4) or
// 4 (quartic, 3 Gauss points, order 6).
template <int S>
struct GalerkinBeanieLayout {
  static_assert(S == 3 || S == 4, "cubic (order 4) or quartic (order 6)");
  static constexpr int bubbles = S - 3, gauss = S - 1;
  static constexpr int aux = 4 * bubbles + 3 * gauss;  // shape bubble, group bubble (3), multipliers
  static constexpr int n = 13 + aux;                   // an interval's coordinates
  static constexpr int unknowns = n - 5;               // a step's
  static constexpr int multipliers = 13 + 4 * bubbles;  // the first multiplier's coordinate
};

// An interval in the engine's coordinates: y = (x, v, Ω0, Ω1, Ω2, X2, V1, O1_0, O1_1, O1_2)
// (x_{n+1} = x + h v + h² X2, v_{n+1} = v + h V1, Ω_{n+1} = Ω + h O1), the group increment
// W = g_n^{-1} g_{n+1} (angle, translation) and aux = ([shape bubble, group bubble (v_x, v_y, ω)],
// three multipliers per Gauss point).
template <int S>
struct GalerkinBeanieInterval {
  Eigen::Matrix<double, 10, 1> y = Eigen::Matrix<double, 10, 1>::Zero();
  double W_angle = 0.0;
  Eigen::Vector2d W_t = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, GalerkinBeanieLayout<S>::aux, 1> aux = Eigen::Matrix<double, GalerkinBeanieLayout<S>::aux, 1>::Zero();
};

// Derivatives in the interval's coordinates (y, δ, aux), W moved to W exp(h δ) (the engine's
// IntervalDerivatives layout).
template <int S>
using GalerkinBeanieVector = Eigen::Matrix<double, GalerkinBeanieLayout<S>::n, 1>;
template <int S>
using GalerkinBeanieMatrix = Eigen::Matrix<double, GalerkinBeanieLayout<S>::n, GalerkinBeanieLayout<S>::n>;
template <int S>
struct GalerkinBeanieDerivatives {
  GalerkinBeanieVector<S> gradient;
  GalerkinBeanieMatrix<S> hessian;  // left unset by galerkin_beanie_gradient
};

// L~ = h Σ_i b_i [½ u² + λ_i · χ] (u = μ ψ'' + V'(ψ), χ of BeanieModel) at W exp(h δ): evaluated
// directly, for finite-difference checks of the derivatives below.
template <int S>
double galerkin_beanie_action(const problems::BeanieParameters& par, double h, const GalerkinBeanieInterval<S>& iv,
                              const Eigen::Vector3d& delta = Eigen::Vector3d::Zero());
template <int S>
GalerkinBeanieDerivatives<S> galerkin_beanie_derivatives(const problems::BeanieParameters& par, double h,
                                                         const GalerkinBeanieInterval<S>& iv);
template <int S>
GalerkinBeanieVector<S> galerkin_beanie_gradient(const problems::BeanieParameters& par, double h,
                                                 const GalerkinBeanieInterval<S>& iv);

// The step's unknowns (X2, V1, O1, ζ, aux) of interval n, ζ moving W_n to W_n exp(h ζ); as a
// predictor, W_n = W_{n-1} exp(h ζ). The sensitivity is against the state (interval n-1's
// coordinates, δ moving W_{n-1} to W_{n-1} exp(h δ)).
template <int S>
using GalerkinBeanieUnknowns = Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, 1>;
template <int S>
using GalerkinBeanieSensitivity = Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, GalerkinBeanieLayout<S>::n>;
template <int S>
using GalerkinBeanieStepMatrix =
    Eigen::PartialPivLU<Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, GalerkinBeanieLayout<S>::unknowns>>;

// A flow's memory between steps, as the engine's flow keeps it: the state's derivatives (interval
// n's, once its step is solved) and the factored step matrix, for chord iterations.
template <int S>
struct GalerkinBeanieCarry {
  bool valid = false;
  GalerkinBeanieDerivatives<S> state;
  GalerkinBeanieStepMatrix<S> step_matrix;
};

template <int S>
struct GalerkinBeanieStep {
  GalerkinBeanieInterval<S> next;
  int iterations = 0;
  bool converged = false;
};

// Step n: interval n from interval n-1 (`state`), from `predictor` (else interval n-1's
// unknowns), by chord iterations on the carried step matrix (if any) and then Newton, until
// every correction satisfies |dz_i| <= 1e-12 (1 + |z_i|) (the engine's default test). With
// `sensitivity`: the step matrix at the solution, dz/d(state) by the implicit function theorem
// and the carry moved on to interval n; chord iterations may then end on a predicted last
// correction, and `take_prediction` skips them, the predictor confirmed there by one exact
// Newton correction (solved on by Newton if it is not within 16 tolerances), as the engine's
// flow does (newton.hpp, galerkin_flow.hpp).
template <int S>
GalerkinBeanieStep<S> galerkin_beanie_step(const problems::BeanieParameters& par, double h,
                                           const GalerkinBeanieInterval<S>& state, GalerkinBeanieSensitivity<S>* sensitivity,
                                           GalerkinBeanieCarry<S>* carry = nullptr,
                                           const GalerkinBeanieUnknowns<S>* predictor = nullptr,
                                           bool take_prediction = false);

// `steps` steps from `start` with the sensitivity of the last interval to the first, taken as
// the engine's GalerkinFlow takes them with a seed: predictors extrapolated from the last
// intervals, chord iterations, carried derivatives, predictions taken.
template <int S>
struct GalerkinBeanieFlow {
  GalerkinBeanieInterval<S> last;
  GalerkinBeanieMatrix<S> sensitivity;
  int steps = 0, iterations = 0;  // steps completed, Newton and chord iterations
  bool converged = false;
};
template <int S>
GalerkinBeanieFlow<S> galerkin_beanie_flow(const problems::BeanieParameters& par, double h,
                                           const GalerkinBeanieInterval<S>& start, int steps);

}  // namespace lpshoot::oracles
