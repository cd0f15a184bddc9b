// The beanie's Galerkin 4 step (METHOD.md §9 route (a): cubic Hermite shape, group curve
// g_n exp(ξ) with ξ cubic Hermite in se(2), the constraints at the 2 Gauss points) derived by
// hand: the independent oracle for the engine's derived Galerkin step on SE(2) and its
// sensitivity, and the hand-written baseline of bench/bench_ratios.cpp. The derivation is in
// the .cpp: se(2)'s translations as complex numbers make every group quantity a complex function
// of one angle.
#pragma once

#include <lpshoot/problems/beanie.hpp>

#include <Eigen/LU>

namespace lpshoot::oracles {

// An interval in the engine's coordinates (galerkin.hpp, Galerkin<BeanieModel, 3>):
// y = (x, v, Ω0, Ω1, Ω2, X2, V1, O1_0, O1_1, O1_2) (x_{n+1} = x + h v + h² X2, v_{n+1} = v + h V1,
// Ω_{n+1} = Ω + h O1), the group increment W = g_n^{-1} g_{n+1} (angle, translation) and the
// multipliers (three at each Gauss point).
struct GalerkinBeanieInterval {
  Eigen::Matrix<double, 10, 1> y = Eigen::Matrix<double, 10, 1>::Zero();
  double W_angle = 0.0;
  Eigen::Vector2d W_t = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 6, 1> lambda = Eigen::Matrix<double, 6, 1>::Zero();
};

// Derivatives in the interval's 19 coordinates (y, δ, λ), W moved to W exp(h δ) (the engine's
// IntervalDerivatives layout).
using GalerkinBeanieVector = Eigen::Matrix<double, 19, 1>;
using GalerkinBeanieMatrix = Eigen::Matrix<double, 19, 19>;
struct GalerkinBeanieDerivatives {
  GalerkinBeanieVector gradient;
  GalerkinBeanieMatrix hessian;  // left unset by galerkin4_beanie_gradient
};

// L~ = h Σ_i b_i [½ u² + λ_i · χ] (u = μ ψ'' + V'(ψ), χ of BeanieModel) at W exp(h δ): evaluated
// directly, for finite-difference checks of the derivatives below.
double galerkin4_beanie_action(const problems::BeanieParameters& par, double h, const GalerkinBeanieInterval& iv,
                               const Eigen::Vector3d& delta = Eigen::Vector3d::Zero());
GalerkinBeanieDerivatives galerkin4_beanie_derivatives(const problems::BeanieParameters& par, double h,
                                                       const GalerkinBeanieInterval& iv);
GalerkinBeanieVector galerkin4_beanie_gradient(const problems::BeanieParameters& par, double h,
                                               const GalerkinBeanieInterval& iv);

// The step's unknowns (X2, V1, O1, ζ, λ) of interval n, ζ moving W_n to W_n exp(h ζ), against
// the state (interval n-1's 19 coordinates, δ moving W_{n-1} to W_{n-1} exp(h δ)).
using GalerkinBeanieSensitivity = Eigen::Matrix<double, 14, 19>;
using GalerkinBeanieStepMatrix = Eigen::PartialPivLU<Eigen::Matrix<double, 14, 14>>;

// A flow's memory between steps, as the engine's flow keeps it: the state's derivatives (interval
// n's, once its step is solved) and the factored step matrix, for chord iterations.
struct GalerkinBeanieCarry {
  bool valid = false;
  GalerkinBeanieDerivatives state;
  GalerkinBeanieStepMatrix step_matrix;
};

struct GalerkinBeanieStep {
  GalerkinBeanieInterval next;
  int iterations = 0;
  bool converged = false;
};

// The step's unknowns as a predictor: (X2, V1, O1, ζ, λ) with W_n = W_{n-1} exp(h ζ).
using GalerkinBeanieUnknowns = Eigen::Matrix<double, 14, 1>;

// Step n: interval n from interval n-1 (`state`), from `predictor` (else interval n-1's
// increments), by chord iterations on the carried step matrix (if any) and then Newton, until
// every correction satisfies |dz_i| <= 1e-12 (1 + |z_i|) (the engine's default test). With
// `sensitivity`: the step matrix at the solution, dz/d(state) by the implicit function theorem
// and the carry moved on to interval n; chord iterations may then end on a predicted last
// correction, and `take_prediction` skips them, the predictor confirmed there by one exact
// Newton correction (solved on by Newton if it is not within 16 tolerances), as the engine's
// flow does (newton.hpp, galerkin_flow.hpp).
GalerkinBeanieStep galerkin4_beanie_step(const problems::BeanieParameters& par, double h,
                                         const GalerkinBeanieInterval& state, GalerkinBeanieSensitivity* sensitivity,
                                         GalerkinBeanieCarry* carry = nullptr,
                                         const GalerkinBeanieUnknowns* predictor = nullptr,
                                         bool take_prediction = false);

// `steps` steps from `start` with the sensitivity of the last interval to the first, taken as
// the engine's GalerkinFlow takes them with a seed: predictors extrapolated from the last
// intervals, chord iterations, carried derivatives, predictions taken.
struct GalerkinBeanieFlow {
  GalerkinBeanieInterval last;
  GalerkinBeanieMatrix sensitivity;
  int steps = 0, iterations = 0;  // steps completed, Newton and chord iterations
  bool converged = false;
};
GalerkinBeanieFlow galerkin4_beanie_flow(const problems::BeanieParameters& par, double h,
                                         const GalerkinBeanieInterval& start, int steps);

}  // namespace lpshoot::oracles
