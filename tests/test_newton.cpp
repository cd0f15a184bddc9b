// The step solver's Jacobian reuse (core/newton.hpp), as flows with sensitivities use it: a
// factored matrix carried from a neighbouring step (ChordMatrix) saves Jacobian evaluations,
// lands on the solution a fresh Newton finds, is refreshed when its chord steps stop contracting,
// and a singular matrix is reported and never carried; the step matrices' condition estimate
// against the exact condition number.
#include <lpshoot/core/newton.hpp>

#include <Eigen/LU>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

using namespace lpshoot;

namespace {
using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

// F(z) = A z + c z³ (componentwise) - b: a small nonlinear "step".
struct CubicSystem {
  M3 A;
  double c = 0.1;
  V3 b;
  V3 F(const V3& z) const { return A * z + c * z.array().cube().matrix() - b; }
  M3 J(const V3& z) const {
    M3 j = A;
    j.diagonal() += (3 * c) * z.array().square().matrix();
    return j;
  }
};

struct Solve {
  StepReport report;
  V3 z;
  int jacobians = 0, residuals = 0;
};

// With `noise`, the step equations at tiny h: F is known only to its rounding, which moves the
// corrections by `noise` (relative to z) whatever the iterate. With `growth` (not 1) the noise
// is growth^k noise (1, 1, 1) at the k-th evaluation instead: for growth = -1.5 each correction
// (the difference of two consecutive noises) is 1.5 times the last.
Solve solve(const CubicSystem& sys, V3 z0, ChordMatrix<3>* chord, NewtonOptions opt = {}, double noise = 0,
            double growth = 1) {
  Solve out;
  out.z = z0;
  int calls = 0;
  auto rounding = [&]() -> V3 {
    ++calls;
    if (growth != 1) return V3::Ones() * noise * std::pow(growth, calls);
    return V3(std::sin(12.9898 * calls), std::cos(78.233 * calls), std::sin(3.7 * calls)) * noise;
  };
  out.report = newton_solve<3>(
      7, opt,
      [&](V3& F, M3& J) {
        ++out.jacobians;
        J = sys.J(out.z);
        F = sys.F(out.z) + J * rounding().cwiseProduct(V3::Ones() + out.z.cwiseAbs());
      },
      [&](V3& F) {
        ++out.residuals;
        F = sys.F(out.z) + sys.J(out.z) * rounding().cwiseProduct(V3::Ones() + out.z.cwiseAbs());
      },
      [&](const V3& dz) { out.z += dz; }, [&] { return V3(out.z.cwiseAbs()); }, chord);
  return out;
}

CubicSystem base_system() {
  CubicSystem s;
  s.A << 4, 1, 0, 1, 3, 1, 0, 1, 5;
  s.b = V3(1, 2, 3);
  return s;
}
}  // namespace

TEST(NewtonChord, ANeighboursMatrixSavesJacobiansAndLandsOnTheSameSolution) {
  const CubicSystem first = base_system();
  ChordMatrix<3> chord;
  const Solve a = solve(first, V3::Zero(), &chord);
  ASSERT_EQ(a.report.status, StepStatus::Converged) << a.report.message;
  ASSERT_TRUE(chord.valid);
  EXPECT_GE(a.jacobians, 1);
  // The next "step": slightly different data, from the previous solution as predictor.
  CubicSystem next = first;
  next.b += V3(1e-3, -2e-3, 1e-3);
  const Solve fresh = solve(next, a.z, nullptr);
  const Solve reused = solve(next, a.z, &chord);
  ASSERT_EQ(fresh.report.status, StepStatus::Converged);
  ASSERT_EQ(reused.report.status, StepStatus::Converged) << reused.report.message;
  EXPECT_EQ(fresh.jacobians, 1);
  EXPECT_EQ(reused.jacobians, 0);  // chord steps with the neighbour's matrix contract fast enough
  EXPECT_LT((reused.z - fresh.z).lpNorm<Eigen::Infinity>(), 1e-11);
  EXPECT_LT(next.F(reused.z).lpNorm<Eigen::Infinity>(), 1e-11);
  EXPECT_DOUBLE_EQ(reused.report.condition, chord.condition);
}

TEST(NewtonChord, AMatrixWhoseChordStepsDoNotContractIsRefreshed) {
  const CubicSystem sys = base_system();
  ChordMatrix<3> chord;
  // A poor carried matrix: the exact one of a far-away point (z = (3, -3, 3): cubic terms dominate).
  const V3 far(3, -3, 3);
  chord.lu.compute(sys.J(far));
  chord.condition = condition_number_1(M3(sys.J(far)), chord.lu);
  chord.valid = true;
  const Solve s = solve(sys, V3::Zero(), &chord);
  ASSERT_EQ(s.report.status, StepStatus::Converged) << s.report.message;
  EXPECT_GE(s.jacobians, 1);
  EXPECT_LT(sys.F(s.z).lpNorm<Eigen::Infinity>(), 1e-11);
  // The carried matrix is now one evaluated here, near the solution (an iterate away from it).
  const M3 carried = chord.lu.reconstructed();
  EXPECT_LT((carried - sys.J(s.z)).lpNorm<Eigen::Infinity>(), 0.02 * (sys.J(far) - sys.J(s.z)).lpNorm<Eigen::Infinity>());
}

// A carried matrix whose chord steps contract, but slowly: M = A / 0.76 on the affine F = A z - b
// gives dz = -0.76 (z - z*), so every chord correction is 0.24 times the last. From a correction of
// ~760 the step tolerance (1e-12 (1 + |z_i|), |z_i| >= 700) is 20 chord steps away: one too many
// for 20 iterations. At the rate measured after the second step the chord cannot make it, so the
// matrix is refreshed there, and Newton on the affine equations converges in two more.
TEST(NewtonChord, AChordTooSlowForTheIterationsLeftIsRefreshed) {
  CubicSystem sys = base_system();
  sys.c = 0;
  const V3 solution(1000, -700, 900);
  sys.b = sys.A * solution;
  ChordMatrix<3> chord;
  chord.lu.compute(M3(sys.A / 0.76));
  chord.condition = condition_number_1(M3(sys.A / 0.76), chord.lu);
  chord.valid = true;
  const Solve s = solve(sys, V3::Zero(), &chord);
  ASSERT_EQ(s.report.status, StepStatus::Converged) << s.report.message;
  EXPECT_EQ(s.jacobians, 1);
  EXPECT_LE(s.report.iterations, 5);
  EXPECT_LT((s.z - solution).lpNorm<Eigen::Infinity>(), 1e-12 * 1000);
  // The same chord with iterations to spare (30) is left to converge on its own, at 0.24 a step.
  NewtonOptions patient;
  patient.max_iterations = 30;
  chord.lu.compute(M3(sys.A / 0.76));
  chord.condition = condition_number_1(M3(sys.A / 0.76), chord.lu);
  chord.valid = true;
  const Solve p = solve(sys, V3::Zero(), &chord, patient);
  ASSERT_EQ(p.report.status, StepStatus::Converged) << p.report.message;
  EXPECT_EQ(p.jacobians, 0);
  EXPECT_GE(p.report.iterations, 20);
}

TEST(NewtonChord, ASingularMatrixIsReportedAndNotCarried) {
  CubicSystem sys = base_system();
  sys.A.setZero();  // J(0) = 0
  ChordMatrix<3> chord;
  const Solve s = solve(sys, V3::Zero(), &chord);
  EXPECT_EQ(s.report.status, StepStatus::Singular);
  EXPECT_NE(s.report.message.find("step n=7"), std::string::npos) << s.report.message;
  EXPECT_FALSE(chord.valid);
  // A carried matrix above the condition limit is not used: the step evaluates its own.
  const CubicSystem ok = base_system();
  chord.valid = true;
  chord.condition = 1e20;
  const Solve t = solve(ok, V3::Zero(), &chord);
  ASSERT_EQ(t.report.status, StepStatus::Converged) << t.report.message;
  EXPECT_GE(t.jacobians, 1);
  EXPECT_TRUE(chord.valid);
  EXPECT_LT(chord.condition, 1e3);
}

// The step matrices' LU (core/small_lu.hpp) against Eigen's PartialPivLU: the same pivots, so the
// same factors to rounding, and solves (one column, 26 columns as a Galerkin 6 sensitivity, the
// transpose) with backward errors at rounding, on random, nearly dependent and badly scaled
// 21 x 21 matrices, and on a matrix whose first pivot is zero without an interchange.
TEST(SmallLU, MatchesEigensPartialPivotingAndSolvesToRounding) {
  using M = Eigen::Matrix<double, 21, 21>;
  using V = Eigen::Matrix<double, 21, 1>;
  using B = Eigen::Matrix<double, 21, 26>;
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  auto random = [&](auto& a) {
    for (int i = 0; i < a.rows(); ++i)
      for (int j = 0; j < a.cols(); ++j) a(i, j) = normal(rng);
  };
  double worst_factor = 0, worst_backward = 0;
  for (int t = 0; t < 60; ++t) {
    M J;
    random(J);
    if (t % 3 == 1) J.col(5) = J.col(3) + 1e-9 * J.col(5);
    if (t % 3 == 2)
      for (int i = 0; i < 21; ++i) J.row(i) *= std::pow(10.0, i % 7 - 3);
    SmallLU<21> lu;
    lu.compute(J);
    const Eigen::PartialPivLU<M> eigen(J);
    const double size = J.cwiseAbs().maxCoeff();
    worst_factor = std::max(worst_factor, (lu.factors() - eigen.matrixLU()).cwiseAbs().maxCoeff() /
                                              eigen.matrixLU().cwiseAbs().maxCoeff());
    EXPECT_LT((lu.reconstructed() - J).cwiseAbs().maxCoeff(), 1e-13 * size) << t;
    V b;
    B bs;
    random(b);
    random(bs);
    const double norm_j = J.cwiseAbs().rowwise().sum().maxCoeff();
    const V x = lu.solve(b);
    const B xs = lu.solve(bs);
    const V y = lu.solve_transposed(b);
    // Normwise backward errors |A x - b| / (|A| |x| + |b|), infinity norms.
    auto backward = [&](const auto& r, const auto& x_, const auto& b_, double a) {
      return r.cwiseAbs().maxCoeff() / (a * x_.cwiseAbs().maxCoeff() + b_.cwiseAbs().maxCoeff());
    };
    worst_backward = std::max({worst_backward, backward(J * x - b, x, b, norm_j),
                               backward(J.transpose() * y - b, y, b, J.cwiseAbs().colwise().sum().maxCoeff())});
    for (int c = 0; c < 26; ++c)
      worst_backward = std::max(worst_backward, backward(J * xs.col(c) - bs.col(c), xs.col(c), bs.col(c), norm_j));
  }
  std::printf("small LU: factors against Eigen's %.1e, worst backward error %.1e\n", worst_factor, worst_backward);
  EXPECT_LT(worst_factor, 1e-12);
  EXPECT_LT(worst_backward, 1e-14);
  // A zero leading entry: the first pivot is the second row.
  Eigen::Matrix3d A;
  A << 0, 2, 1, 3, 1, 0, 1, 1, 4;
  SmallLU<3> lu3;
  lu3.compute(A);
  const Eigen::Vector3d b3(1, 2, 3);
  EXPECT_LT((A * lu3.solve(b3) - b3).norm(), 1e-15 * 8);
  EXPECT_LT((A.transpose() * lu3.solve_transposed(b3) - b3).norm(), 1e-15 * 8);
}

TEST(ConditionNumber, HagersEstimateIsALowerBoundWithinASmallFactorOfTheExact) {
  // The step matrices' regularity check (condition_number_1, LAPACK dgecon's estimator) against
  // ||J||_1 ||J^{-1}||_1 from the explicit inverse: random, nearly dependent and badly scaled
  // 21 x 21 matrices (a beanie Galerkin 6 step's size).
  using M = Eigen::Matrix<double, 21, 21>;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  double worst = 1.0, largest = 0.0;
  for (int t = 0; t < 600; ++t) {
    M J;
    for (int i = 0; i < 21; ++i)
      for (int j = 0; j < 21; ++j) J(i, j) = normal(rng);
    if (t % 3 == 1) J.col(5) = J.col(3) + 1e-9 * J.col(5);
    if (t % 3 == 2)
      for (int i = 0; i < 21; ++i) J.row(i) *= std::pow(10.0, i % 7 - 3);
    SmallLU<21> lu;
    lu.compute(J);
    const M inv = J.inverse();
    const double exact = J.cwiseAbs().colwise().sum().maxCoeff() * inv.cwiseAbs().colwise().sum().maxCoeff();
    const double estimate = condition_number_1(J, lu);
    EXPECT_LE(estimate, exact * (1 + 1e-10)) << t;
    worst = std::min(worst, estimate / exact);
    largest = std::max(largest, exact);
  }
  std::printf("condition estimate / exact: worst %.3f over 600 matrices (largest exact %.1e)\n", worst, largest);
  EXPECT_GT(worst, 0.1);
  EXPECT_GT(largest, 1e8);  // the nearly dependent ones are in the sample
  M S = M::Identity();
  S.col(4).setZero();
  SmallLU<21> lu;
  lu.compute(S);
  EXPECT_FALSE(condition_number_1(S, lu) <= 1e13);  // singular: inf or NaN, never a number
}

namespace {
// Ill-conditioned (cond ~ 1e6, as the beanie's Galerkin steps at h = 2e-5).
CubicSystem stiff_system() {
  CubicSystem s = base_system();
  s.A.row(0) *= 1e6;
  s.b(0) *= 1e6;
  return s;
}

double relative_error(const V3& z, const V3& exact) {
  return ((z - exact).cwiseAbs().array() / (1.0 + exact.cwiseAbs().array())).maxCoeff();
}

// Two consecutive steps of the stiff system, the second's data moved by `change` from the first's:
// the first solved by Newton (leaving its matrix in `chord`), the second by a fresh Newton
// (`exact`) and by chord steps from the first's solution with a residual noise of 3e-11
// (`chorded`, polished).
struct NoisyNextStep {
  ChordMatrix<3> chord;
  CubicSystem next = stiff_system();
  Solve previous, exact, chorded;
  NewtonOptions opt;
};
NoisyNextStep noisy_next_step(const V3& change) {
  NoisyNextStep t;
  t.previous = solve(stiff_system(), V3::Zero(), &t.chord);
  t.next.b += change;
  t.exact = solve(t.next, t.previous.z, nullptr);
  t.opt.polish_chord = true;
  t.chorded = solve(t.next, t.previous.z, &t.chord, t.opt, 3e-11);
  return t;
}
}  // namespace

// Chord steps that contracted 4-fold (ρ ≤ 1/4, shown above the noise) and then stall at the
// noise are converged: no fresh Jacobian is evaluated to find that out (before: one per step,
// the most costly part of a Galerkin step at h = 2e-5). The iterate is within the noise of the
// root.
TEST(NewtonChord, ChordStepsThatContractedThenStallAtTheNoiseAreConverged) {
  const NoisyNextStep t = noisy_next_step(V3(1e-1, -2e-7, 1e-7));  // the predictor is ~1e-7 off
  ASSERT_EQ(t.previous.report.status, StepStatus::Converged) << t.previous.report.message;
  ASSERT_EQ(t.exact.report.status, StepStatus::Converged);
  const Solve& s = t.chorded;
  ASSERT_EQ(s.report.status, StepStatus::Converged) << s.report.message;
  EXPECT_GT(t.chord.condition, 1e5);
  EXPECT_EQ(s.jacobians, 0);
  EXPECT_LE(s.report.iterations, 5);
  EXPECT_LT(relative_error(s.z, t.exact.z), 1e-9);
}

// A correction within the step tolerance is polished by chord corrections until one is within
// rounding (16 u) or, far above it (1024 u), does not shrink 4-fold: at a noise between the
// two (from 1e-13 relative, each correction 1.5 times the last), the polish ends after the
// first correction that did not (before: always three).
TEST(NewtonChord, APolishStopsWhenItsCorrectionsStopShrinking) {
  const CubicSystem first = stiff_system();
  ChordMatrix<3> chord;
  const Solve a = solve(first, V3::Zero(), &chord);
  ASSERT_EQ(a.report.status, StepStatus::Converged) << a.report.message;
  CubicSystem next = first;
  next.b += V3(1e-3, -2e-9, 1e-9);
  NewtonOptions opt;
  opt.polish_chord = true;
  const Solve s = solve(next, a.z, &chord, opt, 1e-13, -1.5);
  ASSERT_EQ(s.report.status, StepStatus::Converged) << s.report.message;
  EXPECT_EQ(s.jacobians, 0);
  EXPECT_LE(s.residuals - s.report.iterations, 2) << "polish corrections after convergence";
}

// A predictor already within the noise: the first chord correction is within it (but above the
// step tolerance), the second samples the noise and does not shrink 4-fold, so no contraction
// can be observed. Such a step is converged without a fresh Jacobian (before: one per step, the
// beanie Galerkin 4 flow at h = 2e-5 took 47 µs a step with sensitivities instead of 34), and
// the iterate is within the noise of the root a fresh Newton finds.
TEST(NewtonChord, ChordStepsFromAPredictorWithinTheNoiseAreConverged) {
  const NoisyNextStep t = noisy_next_step(V3(1e-4, -1e-10, 1e-10));  // ~1e-10 off, the noise 3e-11
  ASSERT_EQ(t.previous.report.status, StepStatus::Converged) << t.previous.report.message;
  ASSERT_EQ(t.exact.report.status, StepStatus::Converged);
  const Solve& s = t.chorded;
  ASSERT_EQ(s.report.status, StepStatus::Converged) << s.report.message;
  EXPECT_GT(t.chord.condition, 1e5);  // noise bound min(1e-8, 64 u cond) = 1e-8 relative
  EXPECT_EQ(s.jacobians, 0);
  EXPECT_GE(s.report.iterations, 2);  // the first correction was not within the step tolerance
  EXPECT_LT(relative_error(s.z, t.exact.z), 1e-9);
  // A carried matrix whose chord steps diverge (a fifth of the step's: each correction -4 times
  // the last) is refreshed, even from within the noise, and lands on the same root.
  ChordMatrix<3> poor;
  const M3 fifth = 0.2 * t.next.J(t.previous.z);
  poor.lu.compute(fifth);
  poor.condition = condition_number_1(fifth, poor.lu);
  poor.valid = true;
  const Solve u = solve(t.next, t.previous.z, &poor, t.opt, 3e-11);
  ASSERT_EQ(u.report.status, StepStatus::Converged) << u.report.message;
  EXPECT_GE(u.jacobians, 1);
  EXPECT_LT(relative_error(u.z, t.exact.z), 1e-9);
}
