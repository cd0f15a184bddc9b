// The small dense Newton solver behind every flow step (both discretizations), and the reports
// of a step and of a flow.
//
// Newton from a predictor with an exact Jacobian; after a Newton step, chord steps (same
// factorization, residual only) are taken while they contract by 4x, else the Jacobian is
// refreshed. A flow with sensitivities carries each step's factored matrix at its solution to the
// next step (ChordMatrix), which starts with chord steps on it. The 1-norm condition number of
// every step matrix factored (Hager's estimate, as LAPACK's dgecon) is the regularity diagnostic (paper Proposition 2): above
// NewtonOptions::max_condition the step is reported singular, naming it.
// Everything is fixed size: no allocation in the loop except the failure message.
#pragma once

#include <Eigen/Core>

#include "one_norm_estimate.hpp"
#include "small_lu.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace lpshoot {

enum class StepStatus { Converged, NotConverged, Singular, NonFinite };

struct StepReport {
  int step = -1;  // n
  StepStatus status = StepStatus::NotConverged;
  int iterations = 0;
  double residual = 0;   // max-norm of F at the last evaluation
  double condition = 0;  // 1-norm condition number of ∂F/∂z at the last evaluation
  // Converged by prediction (NewtonOptions::end_on_prediction): the caller must confirm it.
  bool predicted = false;
  // When the step ended at its residual's noise (a correction that stopped shrinking, within the
  // noise): that correction's relative size, a sample of the noise. 0 otherwise.
  double noise_sample = 0;
  std::string message;   // empty when converged
};

// Why a step failed when its equations evaluated to a non-finite number (an overflow, or a NaN
// from the model or the state): every step solver reports it in these words.
inline constexpr char kNonFiniteStep[] = "the step equations evaluated to a non-finite number";

// rep (what the caller filled in) as step n's failure on a non-finite evaluation.
inline StepReport non_finite_step(StepReport rep, int n) {
  rep.step = n;
  rep.status = StepStatus::NonFinite;
  rep.message = "step n=" + std::to_string(n) + ": " + kNonFiniteStep;
  return rep;
}

struct NewtonOptions {
  int max_iterations = 20;
  // Converged when every Newton correction satisfies |dz_i| <= step_tolerance * (1 + |z_i|).
  double step_tolerance = 1e-12;
  // A step whose ∂F/∂z has a larger condition estimate is reported singular.
  double max_condition = 1e13;
  // Problems whose step equations are affine with a constant matrix (core/degree.hpp) factor it
  // once per flow: the chord step is then the Newton step. False: every step evaluates its own.
  bool reuse_constant_matrix = true;
  // A chord step that meets the tolerance leaves an error of ~ρ |dz| (ρ the chord's contraction),
  // against ~|dz|² for a Newton step. With polish_chord chord corrections follow until one is
  // within rounding (at most 3, or until they stop shrinking: the noise), also after chord
  // steps that stalled at the noise (newton_solve): set by flows whose steps end in chord steps
  // and whose momentum map must hold to roundoff (galerkin_flow.hpp).
  bool polish_chord = false;
  // A chord step that contracted 4-fold (rate ρ against the correction before) and after which
  // the next correction, ρ times this one, would be within predicted_step_allowance tolerances
  // ends the solve without the residual that would show it (StepReport::predicted). For callers
  // that evaluate the step at z anyway and confirm there with an exact Newton correction: a
  // flow's step sensitivity (galerkin_flow.hpp, confirm_predicted_step).
  bool end_on_prediction = false;
  // The relative size (|dz_i| / (1 + |z_i|), max over i) of corrections known to be the residual's
  // noise, from earlier steps of the same flow (StepReport::noise_sample); 0: not known.
  double noise_floor = 0;
};

// How far, in step tolerances, the exact Newton correction that confirms a predicted end may
// be (NewtonOptions::end_on_prediction). Applied, it leaves an error O(correction²), far below
// the tolerance; what the allowance bounds is how far from the solution the step's derivatives
// were taken: 16 tolerances, 1.6e-11 relative at the default. At 1 (the tolerance itself) the
// beanie's Galerkin 6 steps at h = 0.01 were predicted to land at 6e-12 and kept their third
// residual.
constexpr double predicted_step_allowance = 16;

// How far, relative to 1 + |z_i|, the exact Newton correction that confirms a predicted step may
// be: predicted_step_allowance tolerances, plus the residual's noise as newton_solve allows at a
// stall (64 u times the step matrix's condition, at most 1e-8).
inline double predicted_step_bound(const NewtonOptions& opt, double condition) {
  return predicted_step_allowance * opt.step_tolerance +
         std::min(1e-8, 64 * std::numeric_limits<double>::epsilon() * condition);
}

enum class FlowStatus { Ok, NotConverged, Singular, NonFinite, InvalidInput };

struct FlowReport {
  FlowStatus status = FlowStatus::Ok;
  std::string message;      // empty when Ok; names the failed step otherwise
  int failed_step = -1;
  int steps = 0;            // steps completed
  int total_iterations = 0;
  int max_iterations = 0;
  double max_residual = 0;
  double max_condition = 0;
  bool ok() const { return status == FlowStatus::Ok; }

  // Accounts for one step; false (with the failure recorded) when it did not converge.
  bool add(const StepReport& sr) {
    total_iterations += sr.iterations;
    max_iterations = std::max(max_iterations, sr.iterations);
    max_residual = std::max(max_residual, sr.residual);
    max_condition = std::max(max_condition, sr.condition);
    if (sr.status == StepStatus::Converged) {
      ++steps;
      return true;
    }
    status = sr.status == StepStatus::Singular    ? FlowStatus::Singular
             : sr.status == StepStatus::NonFinite ? FlowStatus::NonFinite
                                                  : FlowStatus::NotConverged;
    message = sr.message;
    failed_step = sr.step;
    return false;
  }
};

// Short numeric text for messages ("1.2e+16").
inline std::string format_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// ||J||_1 times Hager's estimate of ||J^{-1}||_1 from the LU factors (one_norm_estimate.hpp): a
// handful of solves instead of the inverse's n columns, which cost 6% of a beanie solve. inf or
// NaN if J is singular (a zero pivot).
template <int n>
double condition_number_1(const Eigen::Matrix<double, n, n>& J, const SmallLU<n>& lu) {
  using V = Eigen::Matrix<double, n, 1>;
  const double inverse_norm = inverse_one_norm_estimate<V>([&](const V& b) -> V { return lu.solve(b); },
                                                           [&](const V& b) -> V { return lu.solve_transposed(b); }, n);
  return J.cwiseAbs().colwise().sum().maxCoeff() * inverse_norm;
}

inline bool all_finite(const double* x, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(x[i])) return false;
  return true;
}

// The report of a step whose matrix (paper Proposition 2) is singular or too ill-conditioned.
inline std::string singular_step_reason(double condition, double max_condition) {
  return "the step matrix (Proposition 2) is singular (condition " + format_number(condition) + " > " +
         format_number(max_condition) + ")";
}

// A factored step matrix for chord iterations: the exact matrix of a flow's previous step at its
// solution (the sensitivity computes and factors it anyway). Valid only when regular. Flows
// without sensitivities do not carry one: chord-solved steps are accurate to the step tolerance
// only, Newton-solved ones to roundoff, and the discrete momentum map adds up the difference
// (bench/RESULTS.md, "Reusing Jacobians across steps and Newton iterations").
template <int n>
struct ChordMatrix {
  SmallLU<n> lu;
  double condition = 0;  // 1-norm condition number of the factored matrix
  bool valid = false;
};

// dz/d(state) = -(∂F/∂z)^{-1} ∂F/∂(state) at a solved step (the implicit function theorem),
// from J = [∂F/∂z  ∂F/∂(state)], leaving ∂F/∂z factored in `chord` (if given) with its 1-norm
// condition number, also returned in `condition` (the regularity check at the solution; a flow
// stops at a singular one, so the matrix is marked valid for chord steps).
template <int nz, int ns>
Eigen::Matrix<double, nz, ns> implicit_sensitivity(const Eigen::Matrix<double, nz, nz + ns>& J, ChordMatrix<nz>* chord,
                                                   double* condition) {
  ChordMatrix<nz> own;
  ChordMatrix<nz>& factored = chord ? *chord : own;
  const Eigen::Matrix<double, nz, nz> Jz = J.template leftCols<nz>();
  factored.lu.compute(Jz);
  factored.condition = condition_number_1(Jz, factored.lu);
  factored.valid = true;
  if (condition) *condition = factored.condition;
  return -factored.lu.solve(Eigen::Matrix<double, nz, ns>(J.template rightCols<ns>()));
}

// Solves F(z) = 0 for a step with n unknowns. The callbacks:
//   jacobian(F, J): F and ∂F/∂z at the current z;  residual(F): F only;
//   correct(dz): z <- z ⊕ dz;  magnitude(): |z_i| for the convergence test (0 for group parts).
// `chord`, when given and valid, is a neighbouring step's factored matrix (ChordMatrix): the
// first iterations are chord steps with it, and the exact Jacobian is evaluated only when they
// stop contracting by 4x (the Jacobian reuse of implicit integrators; the converged z is the
// same, to the step tolerance). A Jacobian evaluated here is left in `chord` for the next step.
// `affine`: the equations are affine and the matrix (chord or evaluated) is theirs, so the first
// correction solves them to rounding and no confirming evaluation is made.
template <int n, class Jacobian, class Residual, class Correct, class Magnitude>
StepReport newton_solve(int step, const NewtonOptions& opt, Jacobian&& jacobian, Residual&& residual, Correct&& correct,
                        Magnitude&& magnitude, ChordMatrix<n>* chord = nullptr, bool affine = false) {
  StepReport rep;
  rep.step = step;
  auto fail = [&](StepStatus st, const std::string& why) {
    rep.status = st;
    rep.message = "step n=" + std::to_string(step) + ": " + why;
    return rep;
  };
  using Vn = Eigen::Matrix<double, n, 1>;
  Vn F;
  Eigen::Matrix<double, n, n> J;
  std::optional<ChordMatrix<n>> own;  // only without a caller's: its zeroing cost a flow step ~4%
  ChordMatrix<n>& factored = chord ? *chord : own.emplace();
  auto& lu = factored.lu;
  bool refresh = !(factored.valid && factored.condition <= opt.max_condition);
  if (!refresh) rep.condition = factored.condition;
  double last_step = std::numeric_limits<double>::infinity();
  double last_residual = std::numeric_limits<double>::infinity();
  bool chord_contracted = false;
  bool last_chord_within_noise = false;  // the last correction was a chord step's, within the noise
  constexpr double eps = std::numeric_limits<double>::epsilon();
  for (int it = 1; it <= opt.max_iterations; ++it) {
    rep.iterations = it;
    if (refresh) {
      jacobian(F, J);
      if (!all_finite(F.data(), n) || !all_finite(J.data(), n * n))
        return fail(StepStatus::NonFinite, kNonFiniteStep);
      lu.compute(J);
      rep.condition = condition_number_1(J, lu);
      factored.condition = rep.condition;
      factored.valid = rep.condition <= opt.max_condition;
      if (!factored.valid) return fail(StepStatus::Singular, singular_step_reason(rep.condition, opt.max_condition));
    } else {
      residual(F);
      if (!all_finite(F.data(), n)) return fail(StepStatus::NonFinite, kNonFiniteStep);
    }
    rep.residual = F.template lpNorm<Eigen::Infinity>();
    const Vn dz = lu.solve(-F);
    const Vn scale = magnitude();
    correct(dz);
    // Polish: chord corrections until one is within rounding (16 u relative; at most 3), or one
    // far above it (1024 u) does not shrink 4-fold: the residual's noise at tiny h, which
    // further corrections only sample (beanie Galerkin 4 at h = 2e-5: ~5e-12 relative, every
    // step polished 3 times before). Closer to rounding the three go on (spherical pendulum
    // scene: momentum drift 1.3e-15; 5.7e-15 when any correction that does not shrink ends it).
    auto polish = [&](double last) {
      for (int p = 0; p < 3 && opt.polish_chord && !refresh && !affine; ++p) {
        residual(F);
        if (!all_finite(F.data(), n)) return false;
        const Vn fine = lu.solve(-F);
        const Vn fine_scale = magnitude();
        correct(fine);
        if (((fine.cwiseAbs().array() - 16 * eps * (1.0 + fine_scale.array())) <= 0.0).all()) break;
        const double size = fine.template lpNorm<Eigen::Infinity>();
        const bool above_rounding = ((fine.cwiseAbs().array() - 1024 * eps * (1.0 + fine_scale.array())) > 0.0).any();
        if (above_rounding && size > 0.25 * last) break;
        last = size;
      }
      return true;
    };
    const double size = dz.template lpNorm<Eigen::Infinity>();
    if (affine || ((dz.cwiseAbs().array() - opt.step_tolerance * (1.0 + scale.array())) <= 0.0).all()) {
      if (!polish(size)) return fail(StepStatus::NonFinite, kNonFiniteStep);
      rep.status = StepStatus::Converged;
      return rep;
    }
    // A chord step that contracted 4-fold to within twice the flow's known noise, after which the
    // next correction (ρ times this one) would be a quarter of the noise: further corrections
    // would sample the noise, not reduce the error.
    if (opt.noise_floor > 0 && !refresh && std::isfinite(last_step) && size <= 0.25 * last_step) {
      const double relative = (dz.cwiseAbs().array() / (1.0 + scale.array())).maxCoeff();
      if (relative <= 2 * opt.noise_floor && (size / last_step) * relative <= 0.25 * opt.noise_floor) {
        rep.status = StepStatus::Converged;
        return rep;
      }
    }
    if (opt.end_on_prediction && !refresh && std::isfinite(last_step) && size <= 0.25 * last_step) {
      const double rho = size / last_step;
      if (((rho * dz.cwiseAbs().array() - predicted_step_allowance * opt.step_tolerance * (1.0 + scale.array())) <= 0.0).all()) {
        rep.status = StepStatus::Converged;
        rep.predicted = true;
        return rep;
      }
    }
    // At the roundoff floor (tiny h: terms of size 1/h cancel to an O(1) residual) F is rounding
    // noise and stops decreasing; the correction it yields is then ~ cond(J) u relative, which
    // may exceed step_tolerance. A fresh-Jacobian step on a stalled residual, or whose correction
    // did not shrink 4-fold (exact Newton contracts quadratically above the noise; a noisy
    // residual can dip below the last one and return, tests/test_extremes.cpp), with a
    // correction within that noise (never beyond 1e-8 relative) is converged: another iteration
    // cannot do better.
    // So is a chord step's whose correction did not shrink 4-fold, once an earlier chord step of
    // this solve did (ρ ≤ 1/4 measured above the noise: the stall is likely noise), then polished
    // (polish_chord), which goes on while its corrections shrink (a slower contraction than
    // measured) and so ends within rounding wherever the noise allows it. No fresh Jacobian is
    // evaluated to find that out (beanie Galerkin 4 at h = 2e-5: one per step before).
    // So, finally, is a chord step's that did not double, after a chord correction already
    // within that noise: the predictor was within the noise, and corrections that neither shrink
    // 4-fold nor double are sampling it (two noise samples differ by up to 2x either way; a
    // chord that diverges from there leaves at most a few corrections' size). Beanie Galerkin 4
    // at h = 2e-5: the predictor is within ~1e-12 relative, and each step evaluated a fresh
    // Jacobian to find that out, 47 µs a step with sensitivities against 34 at h = 0.01.
    const double noise = std::min(1e-8, 64 * eps * rep.condition);
    auto within_noise = [&](const Vn& x, const Vn& x_scale) {
      return ((x.cwiseAbs().array() - (opt.step_tolerance + noise) * (1.0 + x_scale.array())) <= 0.0).all();
    };
    const bool stalled = refresh ? rep.residual > 0.25 * last_residual || size > 0.25 * last_step
                                 : (chord_contracted || (last_chord_within_noise && size <= 2 * last_step)) &&
                                       size > 0.25 * last_step;
    if (stalled) {
      if (within_noise(dz, scale)) {
        rep.noise_sample = (dz.cwiseAbs().array() / (1.0 + scale.array())).maxCoeff();
        if (!refresh && !polish(size)) return fail(StepStatus::NonFinite, kNonFiniteStep);
        rep.status = StepStatus::Converged;
        return rep;
      }
    }
    last_residual = rep.residual;
    last_chord_within_noise = !refresh && within_noise(dz, scale);
    if (!refresh && last_step < std::numeric_limits<double>::infinity() && size <= 0.25 * last_step) chord_contracted = true;
    // A chord step is refreshed when it contracts less than 4-fold, or when at the rate ρ it
    // measured it cannot meet the tolerance in the iterations left: the test of RADAU5's
    // simplified Newton (Hairer & Wanner, Solving ODEs II, §IV.8). Beanie Galerkin 6 at
    // V = 3000 (1 − cos ψ), a step from the guess: chord steps at ρ ≈ 0.22 for 20 iterations,
    // from a first correction of 755 down to 4e-12, and the flow failed.
    auto too_slow = [&] {
      const double rho = size / last_step;  // 0 on the first iteration (no last step yet)
      const double excess = (dz.cwiseAbs().array() / (opt.step_tolerance * (1.0 + scale.array()))).maxCoeff();
      return rho > 0 && excess > 1 && std::log(excess) > (opt.max_iterations - it) * std::log(1 / rho);
    };
    refresh = refresh ? false : !(size <= 0.25 * last_step) || too_slow();
    last_step = size;
  }
  return fail(StepStatus::NotConverged, "Newton did not converge in " + std::to_string(opt.max_iterations) +
                                            " iterations (residual " + format_number(rep.residual) + ")");
}

}  // namespace lpshoot
