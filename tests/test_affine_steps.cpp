// Problems whose step equations are affine (core/degree.hpp): the degree probe tells them from
// the others, and their flows, which factor one step matrix for the whole flow and reuse the
// step's sensitivity, give the same trajectory and sensitivities as flows that evaluate and
// factor the exact matrix at every step (paper scheme and Galerkin), the sensitivities also
// against central differences, which are exact up to rounding for an affine flow; and a shooting
// solve, where KINSOL keeps the first Jacobian's factorization, equals one with a Jacobian per
// iteration.
#include <lpshoot/problems/beanie.hpp>
#include <lpshoot/problems/electron_bvp.hpp>
#include <lpshoot/problems/electron_exact.hpp>

#include <gtest/gtest.h>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {

// ℓ = ½ |p''|² + c p₁ p₂, χ = p'₁ - 1: quadratic with a linear constraint.
struct LinearConstraint {
  using Group = Trivial;
  static constexpr int shape_dim = 2;
  static constexpr int num_constraints = 1;
  double c = 0.3;
  template <class T>
  T lagrangian(const Jet<LinearConstraint, T>& q) const {
    return 0.5 * q.ddp.squaredNorm() + c * q.p(0) * q.p(1);
  }
  template <class T>
  Vec<T, 1> constraints(const Jet<LinearConstraint, T>& q) const {
    return Vec<T, 1>(q.dp(0) - 1.0);
  }
};

// The same with the unit-speed constraint χ = ½ (|p'|² - 1): not affine.
struct QuadraticConstraint : LinearConstraint {
  template <class T>
  T lagrangian(const Jet<QuadraticConstraint, T>& q) const {
    return 0.5 * q.ddp.squaredNorm();
  }
  template <class T>
  Vec<T, 1> constraints(const Jet<QuadraticConstraint, T>& q) const {
    return Vec<T, 1>(0.5 * (q.dp.squaredNorm() - 1.0));
  }
};

// A quadratic on each side of p₁ = 0, chosen by a branch: piecewise, not affine.
struct Branching {
  using Group = Trivial;
  static constexpr int shape_dim = 1;
  static constexpr int num_constraints = 0;
  template <class T>
  T lagrangian(const Jet<Branching, T>& q) const {
    const T stiffness = value(q.p(0)) > 0 ? T(1.0) : T(2.0);
    return 0.5 * q.ddp(0) * q.ddp(0) + stiffness * q.p(0) * q.p(0);
  }
};

// ½ p₀''²: quadratic, but p₁ does not enter, so every step matrix is singular.
struct MissingCoordinate {
  using Group = Trivial;
  static constexpr int shape_dim = 2;
  static constexpr int num_constraints = 0;
  template <class T>
  T lagrangian(const Jet<MissingCoordinate, T>& q) const {
    return 0.5 * q.ddp(0) * q.ddp(0);
  }
};

// ½ |p''|² / m + √(1 + p'²): the root is not a polynomial.
struct WithRoot {
  using Group = Trivial;
  static constexpr int shape_dim = 1;
  static constexpr int num_constraints = 0;
  double m = 2.0;
  template <class T>
  T lagrangian(const Jet<WithRoot, T>& q) const {
    using std::sqrt;
    return 0.5 * q.ddp(0) * q.ddp(0) / m + sqrt(1.0 + q.dp(0) * q.dp(0));
  }
};

ElectronModel nonlinear_electron() {
  ElectronModel e;
  e.potential = 0.5, e.quartic = 0.125;  // METHOD.md §9's nonlinear electron-type problem
  return e;
}

NewtonOptions every_step() {
  NewtonOptions o;
  o.reuse_constant_matrix = false;
  return o;
}

// Largest relative difference of two matrices (scale: the larger entry of `a`, at least 1).
double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>() / std::max(1.0, a.lpNorm<Eigen::Infinity>());
}

template <class Sch>
Interval<Sch, double> electron_start() {
  Interval<Sch, double> iv;
  iv.x << 1.0, 0.0, 0.5;
  iv.v << 0.0, 1.0, -0.2;
  iv.X2 << -0.2, 0.1, 0.05;
  iv.V1 << -0.4, 0.3, 0.1;
  for (int a = 0; a < Sch::aux; ++a) iv.w(a) = 0.01 * (a + 1);
  return iv;
}

// The affine Galerkin flow against one that factors the exact matrix at every step, and its
// sensitivity against central differences (exact for an affine map, up to rounding).
template <class Sch>
void expect_affine_galerkin_flow(double h, int steps) {
  constexpr int ns = Sch::state;
  const ElectronModel e;
  const GalerkinFlow<Sch> affine(e, h), newton(e, h, every_step());
  ASSERT_TRUE(affine.affine());
  ASSERT_FALSE(newton.affine());
  const auto start = electron_start<Sch>();
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(ns, ns);
  const auto a = affine.run(start, steps, &seed), b = newton.run(start, steps, &seed);
  ASSERT_TRUE(a.report.ok()) << a.report.message;
  ASSERT_TRUE(b.report.ok()) << b.report.message;
  // Both solve every step to roundoff; what differs is rounding, amplified by the flow at most
  // like its sensitivity: 1e-14 per step times |S| bounds it (a chord solve to the step
  // tolerance instead of roundoff would leave ~1e-12 per step).
  const double amplification = std::max(1.0, b.sensitivity.template lpNorm<Eigen::Infinity>());
  double worst_state = 0;
  for (int n = 0; n <= steps; ++n)
    worst_state = std::max(worst_state, state_difference(a.trajectory.intervals[n], b.trajectory.intervals[n], h)
                                                .template lpNorm<Eigen::Infinity>());
  const double worst_sensitivity = relative_difference(b.sensitivity, a.sensitivity);
  // Central differences of an affine map: no truncation, rounding ~ u |S| |state| / eps.
  const double eps = 1e-3;
  double worst_fd = 0;
  for (int j = 0; j < ns; ++j) {
    auto end_after = [&](double s) {
      Vec<double, ns> delta = Vec<double, ns>::Zero();
      delta(j) = s;
      const auto r = affine.run(retract<Sch>(start, delta, h), steps, nullptr);
      EXPECT_TRUE(r.report.ok()) << r.report.message;
      return Vec<double, ns>(state_difference(r.trajectory.intervals.back(), a.trajectory.intervals.back(), h));
    };
    const Vec<double, ns> fd = (end_after(eps) - end_after(-eps)) / (2 * eps);
    worst_fd = std::max(worst_fd, (a.sensitivity.col(j) - fd).template lpNorm<Eigen::Infinity>() / amplification);
  }
  std::printf("degree %d, h = %g, %d steps (|S| = %.1e): affine vs Newton: states %.1e, sensitivity %.1e; "
              "sensitivity vs central differences %.1e\n",
              Sch::degree, h, steps, amplification, worst_state, worst_sensitivity, worst_fd);
  EXPECT_LT(worst_state, 1e-14 * steps * amplification);
  EXPECT_LT(worst_sensitivity, 1e-15 * steps);
  EXPECT_LT(worst_fd, 1e-8);
}

// The largest residual of a flow's steps, each evaluated afresh from the model at the flow's
// intervals (interval n-1 as the state, interval n as the unknowns), relative to 1 + the largest
// |unknown|.
template <class Sch>
double worst_model_residual(const typename Sch::Model& model, const GalerkinFlowResult<Sch>& flow, double h) {
  double worst = 0;
  const auto& ivs = flow.trajectory.intervals;
  for (size_t n = 1; n < ivs.size(); ++n) {
    const auto fixed = flat_left_rows<Sch>(flat_interval_gradient<Sch>(model, ivs[n - 1], h), h);
    const Vec<double, Sch::unknowns> F = galerkin_step_residual<Sch>(model, h, ivs[n - 1], ivs[n], fixed);
    worst = std::max(worst, F.template lpNorm<Eigen::Infinity>() /
                                (1.0 + unknowns_magnitude<Sch>(ivs[n]).template lpNorm<Eigen::Infinity>()));
  }
  return worst;
}

// An affine flow's steps after the first take their residual from the constant interval
// Hessian and one reference interval (galerkin_affine.hpp), not from the model. Evaluated afresh
// from the model, every step's equations hold to the rounding level of the flow that solves
// each step by Newton on the model: over a long flow (the coordinates far from the reference
// interval's), without and with sensitivities, with bubbles and with a multiplier.
template <class Sch>
void expect_mapped_steps_solve_the_model(const typename Sch::Model& model, const Interval<Sch, double>& start, double h,
                                         int steps) {
  const GalerkinFlow<Sch> affine(model, h), newton(model, h, every_step());
  ASSERT_TRUE(affine.affine());
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Sch::state, Sch::state);
  for (const Eigen::MatrixXd* s : {static_cast<const Eigen::MatrixXd*>(nullptr), &seed}) {
    const auto a = affine.run(start, steps, s), b = newton.run(start, steps, s);
    ASSERT_TRUE(a.report.ok()) << a.report.message;
    ASSERT_TRUE(b.report.ok()) << b.report.message;
    EXPECT_LE(a.report.total_iterations, steps + 2);  // one residual per step after the first
    const double ra = worst_model_residual(model, a, h), rb = worst_model_residual(model, b, h);
    const double moved = (flat_interval_coordinates(a.trajectory.intervals.back()) - flat_interval_coordinates(start))
                             .template lpNorm<Eigen::Infinity>();
    std::printf("degree %d, m = %d, %d steps%s (coordinates moved by %.1e): worst step residual, affine %.1e, "
                "Newton %.1e\n",
                Sch::degree, Sch::m, steps, s ? ", seeded" : "", moved, ra, rb);
    EXPECT_GT(moved, 10.0);  // far from the reference interval
    EXPECT_LT(ra, 10 * rb + 1e-15);
  }
}

// The largest residual of a paper-scheme flow's steps, each evaluated afresh from the problem at
// the flow's nodes (step n's state and unknowns), relative to 1 + the largest |unknown|.
template <class P>
double worst_paper_residual(const P& problem, const Trajectory<P>& tr, double h) {
  constexpr int k = P::order;
  double worst = 0;
  for (int n = k; n + k <= tr.N(); ++n) {
    const FlowState<P> s = tr.state(n);
    StepUnknowns<P> z;
    z.p = tr.p[n + k];
    z.g = tr.g[n + k - 1];
    z.lam = tr.lam[n];
    const auto F = step_residual(problem, h, s, z, step_fixed_part(problem, h, s, z));
    worst = std::max(worst, F.template lpNorm<Eigen::Infinity>() /
                                (1.0 + step_magnitude(z).template lpNorm<Eigen::Infinity>()));
  }
  return worst;
}

// The paper electron's step residual in long double at a flow's nodes (its E_n written by hand:
// h Σ_j (∂U_j/∂x_n)ᵀ U_j over windows n-2 .. n, Electron's U), relative to 1 + |x_{n+2}|: the
// residual of the stored nodes themselves, without the rounding of evaluating it in double.
double worst_exact_electron_residual(const Electron& e, const Trajectory<Electron>& tr, double h) {
  using LD = long double;
  using M = Eigen::Matrix<LD, 3, 3>;
  using V = Eigen::Matrix<LD, 3, 1>;
  M X;  // B ×
  X << 0, -e.B(2), e.B(1), e.B(2), 0, -e.B(0), -e.B(1), e.B(0), 0;
  const LD hh = h, a = LD(e.mass) / (hh * hh), beta = e.e_over_c, kappa = e.potential;
  const M I = M::Identity();
  const M C0 = (a + 2 * kappa) * I - (beta / hh) * X, C1 = -2 * a * I + (beta / hh) * X, C2 = a * I;
  auto x = [&](int i) { return V(tr.p[i].cast<LD>()); };
  auto U = [&](int j) { return V(a * (x(j + 2) - 2 * x(j + 1) + x(j)) + 2 * kappa * x(j) + (beta / hh) * X * (x(j + 1) - x(j))); };
  double worst = 0;
  for (int n = 2; n + 2 <= tr.N(); ++n) {
    const V E = hh * (C2.transpose() * U(n - 2) + C1.transpose() * U(n - 1) + C0.transpose() * U(n));
    worst = std::max(worst, double(E.cwiseAbs().maxCoeff() / (1 + tr.p[n + 2].cwiseAbs().maxCoeff())));
  }
  return worst;
}

// The paper scheme's counterpart of expect_mapped_steps_solve_the_model: an affine flow without
// a group takes its steps after the first from the constant window Hessian (paper_affine.hpp).
// Its steps' residuals (worst_residual of a trajectory) are those of a flow that solves every
// step by Newton on the problem, up to 3x, without and with sensitivities, far from the
// reference window. (Forming the window gradient as H (x - x_ref) instead, in node coordinates,
// left 10x; keeping the gradient moved by H times the correction rather than at the rounded
// node, 3x on the electron's exact residual.)
template <class P, class Residual>
void expect_mapped_paper_steps_solve_the_problem(const P& problem, const FlowState<P>& start, double h, int N,
                                                 const char* name, Residual&& worst_residual) {
  const DiscreteFlow<P> affine(problem, h), newton(problem, h, every_step());
  ASSERT_TRUE(affine.affine());
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Dims<P>::state, Dims<P>::state);
  for (const Eigen::MatrixXd* s : {static_cast<const Eigen::MatrixXd*>(nullptr), &seed}) {
    const auto a = affine.run(start, N, s), b = newton.run(start, N, s);
    ASSERT_TRUE(a.report.ok()) << a.report.message;
    ASSERT_TRUE(b.report.ok()) << b.report.message;
    const int steps = N - 2 * P::order + 1;
    EXPECT_LE(a.report.total_iterations, steps + 2);  // one residual per step after the first
    const double ra = worst_residual(a.trajectory), rb = worst_residual(b.trajectory);
    const double moved = (a.trajectory.p.back() - start.p[0]).template lpNorm<Eigen::Infinity>();
    std::printf("%s, %d steps%s (nodes moved by %.1e): worst step residual, affine %.1e, Newton %.1e\n", name, steps,
                s ? ", seeded" : "", moved, ra, rb);
    EXPECT_GT(moved, 10.0);  // far from the reference window
    EXPECT_LT(ra, 3 * rb + 1e-15);
  }
}

}  // namespace

TEST(DegreeProbe, CountsPolynomialDegrees) {
  const Degree x = Degree::variable(0.5), y = Degree::variable(-2.0), c(3.0);
  EXPECT_EQ((x * y + c * x).deg, 2);
  EXPECT_EQ((x * x * x).deg, 3);
  EXPECT_EQ((Degree(0.0) * x * x * x + x).deg, 1);  // a zero coefficient removes the term
  EXPECT_EQ(pow(x, 2.0).deg, 2);
  EXPECT_EQ(pow(x, 0.5).deg, Degree::non_polynomial);
  EXPECT_EQ((x / c).deg, 1);
  EXPECT_EQ((c / x).deg, Degree::non_polynomial);
  EXPECT_EQ(sin(c).deg, 0);
  EXPECT_EQ(cos(x).deg, Degree::non_polynomial);
  EXPECT_DOUBLE_EQ((x * y + c * x).v, 0.5 * -2.0 + 3.0 * 0.5);
}

TEST(DegreeProbe, TellsAffineStepsFromOthers) {
  EXPECT_TRUE(model_is_quadratic(ElectronModel{}));
  EXPECT_FALSE(model_is_quadratic(nonlinear_electron()));
  EXPECT_TRUE(model_is_quadratic(LinearConstraint{}));
  EXPECT_FALSE(model_is_quadratic(QuadraticConstraint{}));
  EXPECT_FALSE(model_is_quadratic(Branching{}));
  EXPECT_FALSE(model_is_quadratic(WithRoot{}));
  EXPECT_FALSE(model_is_quadratic(BeanieModel{}));  // a group: never affine here
  EXPECT_TRUE(discrete_problem_is_quadratic(Electron{}, 0.01));
  EXPECT_FALSE(discrete_problem_is_quadratic(BeanieControl{}, 0.01));
  // The flows follow the probe and the option.
  using Flow = GalerkinFlow<Galerkin<ElectronModel, 3>>;
  EXPECT_TRUE(Flow(ElectronModel{}, 0.1).affine());
  EXPECT_FALSE(Flow(nonlinear_electron(), 0.1).affine());
  EXPECT_FALSE(Flow(ElectronModel{}, 0.1, every_step()).affine());
  EXPECT_TRUE(DiscreteFlow<Electron>(Electron{}, 0.1).affine());
  EXPECT_FALSE(DiscreteFlow<Electron>(Electron{}, 0.1, every_step()).affine());
}

TEST(AffineFlows, GalerkinElectronEqualsNewtonAtEveryStep) {
  expect_affine_galerkin_flow<Galerkin<ElectronModel, 3>>(0.01, 300);
  expect_affine_galerkin_flow<Galerkin<ElectronModel, 4>>(0.02, 150);
}

// An affine flow takes step 1's matrix and sensitivity from the start interval's Hessian
// (galerkin_flow.hpp, affine_start); a singular one is still reported at step 1, with and
// without sensitivities, as by the flow that evaluates every step's matrix.
TEST(AffineFlows, ASingularAffineStepIsReportedAtStepOne) {
  using Sch = Galerkin<MissingCoordinate, 3>;
  Interval<Sch, double> start;
  start.x << 0.3, -0.2, start.v << 1.0, 0.5, start.X2 << 0.0, 0.1, start.V1 << 0.0, -0.2;
  const GalerkinFlow<Sch> affine(MissingCoordinate{}, 0.05), newton(MissingCoordinate{}, 0.05, every_step());
  ASSERT_TRUE(affine.affine());
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Sch::state, Sch::state);
  for (const Eigen::MatrixXd* s : {&seed, static_cast<const Eigen::MatrixXd*>(nullptr)}) {
    const auto a = affine.run(start, 10, s), b = newton.run(start, 10, s);
    EXPECT_EQ(a.report.status, FlowStatus::Singular) << a.report.message;
    EXPECT_EQ(a.report.failed_step, 1);
    EXPECT_EQ(a.report.steps, 0);
    EXPECT_NE(a.report.message.find("step n=1: the step matrix (Proposition 2) is singular"), std::string::npos)
        << a.report.message;
    EXPECT_EQ(a.report.message, b.report.message);
  }
}

TEST(AffineFlows, MappedStepsSolveTheModelsEquationsToTheRoundingLevel) {
  expect_mapped_steps_solve_the_model<Galerkin<ElectronModel, 3>>(ElectronModel{}, electron_start<Galerkin<ElectronModel, 3>>(),
                                                                  0.01, 3000);
  expect_mapped_steps_solve_the_model<Galerkin<ElectronModel, 4>>(ElectronModel{}, electron_start<Galerkin<ElectronModel, 4>>(),
                                                                  0.02, 1500);
  using Sch = Galerkin<LinearConstraint, 3>;
  Interval<Sch, double> start;
  start.x << 0.3, -0.2, start.v << 1.0, 0.5, start.X2 << 0.0, 0.1, start.V1 << 0.0, -0.2;
  start.w.setConstant(0.05);
  expect_mapped_steps_solve_the_model<Sch>(LinearConstraint{}, start, 0.05, 400);
}

// The paper electron's residual is measured exactly (long double): evaluated in double, its L_d
// rounds by ~2 units in the last place of a node, and a Newton flow on that L_d picks nodes where
// its own rounding is small (3.3e-10 against 1.4e-10 for the mapped flow's nodes, whose exact
// residual is the Newton flow's or below). The derived windows' residuals are evaluated afresh.
TEST(AffineFlows, MappedPaperStepsSolveTheProblemsEquationsToTheRoundingLevel) {
  const double h = 0.01;
  FlowState<Electron> s;
  const Eigen::Vector3d x0(1, 0, 0.5), v0(0, 1, -0.2), a0(0.3, -0.1, 0.2);
  for (int i = 0; i < 4; ++i) s.p[i] = x0 + i * h * v0 + 0.5 * (i * h) * (i * h) * a0;
  const Electron e;
  for (int N : {3000, 20000})
    expect_mapped_paper_steps_solve_the_problem(e, s, h, N, "paper electron", [&](const Trajectory<Electron>& tr) {
      return worst_exact_electron_residual(e, tr, h);
    });
  // The derived windows with the nodes rounded to doubles (with their low parts the flow is not
  // mapped: paper_affine.hpp).
  using PW = PaperWindows<ElectronModel, WindowJet::Central, false>;
  FlowState<PW> w;
  w.p = s.p;
  expect_mapped_paper_steps_solve_the_problem(PW{}, w, h, 3000, "derived electron windows",
                                              [&](const Trajectory<PW>& tr) { return worst_paper_residual(PW{}, tr, h); });
  using PC = PaperWindows<LinearConstraint, WindowJet::Central, false>;
  FlowState<PC> c;
  const double hc = 0.05;
  for (int i = 0; i < 4; ++i) c.p[i] = Eigen::Vector2d(0.3 + i * hc, -0.2 + 0.5 * i * hc);
  c.lam[0].setConstant(0.1), c.lam[1].setConstant(0.12);
  expect_mapped_paper_steps_solve_the_problem(PC{}, c, hc, 400, "derived windows with a linear constraint",
                                              [&](const Trajectory<PC>& tr) { return worst_paper_residual(PC{}, tr, hc); });
}

TEST(AffineFlows, GalerkinWithLinearConstraintEqualsNewtonAtEveryStep) {
  using Sch = Galerkin<LinearConstraint, 3>;
  constexpr int ns = Sch::state;
  Interval<Sch, double> start;
  start.x << 0.3, -0.2, start.v << 1.0, 0.5, start.X2 << 0.0, 0.1, start.V1 << 0.0, -0.2;
  start.w.setConstant(0.05);
  const GalerkinFlow<Sch> affine(LinearConstraint{}, 0.05), newton(LinearConstraint{}, 0.05, every_step());
  ASSERT_TRUE(affine.affine());
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(ns, ns);
  const auto a = affine.run(start, 100, &seed), b = newton.run(start, 100, &seed);
  ASSERT_TRUE(a.report.ok()) << a.report.message;
  ASSERT_TRUE(b.report.ok()) << b.report.message;
  const double amplification = std::max(1.0, b.sensitivity.lpNorm<Eigen::Infinity>());
  const double states = state_difference(a.trajectory.intervals.back(), b.trajectory.intervals.back(), 0.05)
                            .lpNorm<Eigen::Infinity>();
  std::printf("linear constraint, 100 steps (|S| = %.1e): states %.1e, sensitivity %.1e\n", amplification, states,
              relative_difference(b.sensitivity, a.sensitivity));
  EXPECT_LT(states, 1e-13 * amplification);
  EXPECT_LT(relative_difference(b.sensitivity, a.sensitivity), 1e-13);
  // The constraint p'₁ = 1 holds at every node.
  for (int n = 0; n <= 100; ++n) EXPECT_NEAR(a.trajectory.v(n)(0), 1.0, 1e-12) << "node " << n;
}

TEST(AffineFlows, PaperElectronEqualsNewtonAtEveryStep) {
  const Electron e;
  const double h = 0.01;
  const int N = 300;
  FlowState<Electron> s;
  const Eigen::Vector3d x0(1, 0, 0.5), v0(0, 1, -0.2), a0(0.3, -0.1, 0.2);
  for (int i = 0; i < 4; ++i) s.p[i] = x0 + i * h * v0 + 0.5 * (i * h) * (i * h) * a0;
  constexpr int ns = Dims<Electron>::state;
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(ns, ns);
  const auto a = DiscreteFlow<Electron>(e, h).run(s, N, &seed);
  const auto b = DiscreteFlow<Electron>(e, h, every_step()).run(s, N, &seed);
  ASSERT_TRUE(a.report.ok()) << a.report.message;
  ASSERT_TRUE(b.report.ok()) << b.report.message;
  const double amplification = std::max(1.0, b.sensitivity.lpNorm<Eigen::Infinity>());
  double states = 0;
  for (int n = 0; n <= N; ++n)
    states = std::max(states, (a.trajectory.p[n] - b.trajectory.p[n]).lpNorm<Eigen::Infinity>());
  std::printf("paper electron, %d steps (|S| = %.1e): states %.1e, sensitivity %.1e\n", N, amplification, states,
              relative_difference(b.sensitivity, a.sensitivity));
  EXPECT_LT(states, 1e-14 * N * amplification);
  EXPECT_LT(relative_difference(b.sensitivity, a.sensitivity), 1e-15 * N);
}

TEST(AffineShooting, ElectronSolveEqualsOneWithAJacobianPerIteration) {
  // Galerkin 4, multiple shooting (segments auto: 20 of 100 steps). Affine: flows on one step
  // matrix, KINSOL on the first Jacobian. The other: everything evaluated afresh.
  const Electron e{};
  const ElectronBoundary a{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
  const ElectronBoundary z{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};
  const double T = 2.0;
  const int N = 2000;
  const auto bvp = electron_galerkin_bvp<3>(model_of(e), T, N, a, z);
  const auto exact = electron_exact_optimum(e, T, a.position, a.velocity, z.position, z.velocity);
  ShootingOptions affine, fresh;
  affine.method = fresh.method = ShootingMethod::Multiple;
  affine.solver.tolerance = fresh.solver.tolerance = 1e-12;
  fresh.step.reuse_constant_matrix = false;
  const auto ra = solve_bvp(bvp, electron_galerkin_guess<3>(bvp, a, z), affine);
  const auto rf = solve_bvp(bvp, electron_galerkin_guess<3>(bvp, a, z), fresh);
  ASSERT_TRUE(ra.ok()) << ra.message;
  ASSERT_TRUE(rf.ok()) << rf.message;
  EXPECT_EQ(ra.iterations, rf.iterations);
  EXPECT_EQ(ra.residual_history.size(), rf.residual_history.size());
  EXPECT_EQ(ra.rank, ra.unknowns);
  double between = 0, err = 0;
  for (int n = 0; n <= N; ++n) {
    between = std::max(between, (ra.trajectory.x(n) - rf.trajectory.x(n)).lpNorm<Eigen::Infinity>());
    err = std::max(err, (ra.trajectory.x(n) - exact.position(n * bvp.h())).lpNorm<Eigen::Infinity>());
  }
  std::printf("N = %d, %d iterations: affine vs fresh %.1e, error against the exact optimum %.1e (h^4 = %.1e)\n", N,
              ra.iterations, between, err, std::pow(bvp.h(), 4));
  // Both are solved to the tolerance; what differs is rounding (~1e-13 here).
  EXPECT_LT(between, 1e-11);
  EXPECT_LT(std::abs(ra.cost - rf.cost), 1e-12 * std::abs(rf.cost));
  EXPECT_LT(err, 1e-9);  // truncation ~h^4 = 1e-12 times the solution's derivatives
}
