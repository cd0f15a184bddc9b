// Any order k, not only 1 and 2: a k = 3 minimum-jerk problem whose discrete Euler–Lagrange
// equations are sixth differences = 0, so the flow reproduces any quintic exactly (an exact
// oracle), on a group with non-trivial increments; and a k = 3 problem on SE(2) whose spatial
// momentum is conserved and whose sensitivities match finite differences.
#include "helpers.hpp"

#include <gtest/gtest.h>

using namespace lpshoot;

namespace {
// Shape p in R, group R^2 with trivial connection (g~_j = x_{j+1} - x_j):
// L_d = (h/2) (Δ³p_j / h³)^2 + (h/2) |(g~_{j+2} - 2 g~_{j+1} + g~_j) / h³|^2.
struct Jerk {
  using Group = Rn<2>;
  static constexpr int shape_dim = 1, order = 3, num_constraints = 0;
  template <class T>
  T lagrangian(const Window<Jerk, T>& a, double h) const {
    const T jp = (a.p[3](0) - 3.0 * a.p[2](0) + 3.0 * a.p[1](0) - a.p[0](0)) / (h * h * h);
    const Vec<T, 2> jx = (a.g[2] - 2.0 * a.g[1] + a.g[0]) / (h * h * h);
    return 0.5 * h * (jp * jp + jx.squaredNorm());
  }
};

// Shape p in R, G = SE(2), connection rotating by p differences, plus a constraint:
// L_d = (h/2)(Δ³p/h³)^2 + h^4 |Δ² coords(g~)/h³|^2 - h cos p_1, chi = Δ²angle/h.
struct Se2Order3 {
  using Group = SE2;
  static constexpr int shape_dim = 1, order = 3, num_constraints = 1;
  template <class T>
  T lagrangian(const Window<Se2Order3, T>& a, double h) const {
    using std::cos;
    const T jp = (a.p[3](0) - 3.0 * a.p[2](0) + 3.0 * a.p[1](0) - a.p[0](0)) / (h * h * h);
    // Second differences of the increments' coordinates (t, angle): couples g~_j and g~_{j+2}.
    const Eigen::Matrix<T, 2, 1> jt = (a.g[2].t - 2.0 * a.g[1].t + a.g[0].t) / (h * h * h);
    const T jw = (a.g[2].angle - 2.0 * a.g[1].angle + a.g[0].angle) / (h * h * h);
    const T kinetic = h * h * h * h * (jt.squaredNorm() + 2.0 * jw * jw);
    return 0.5 * h * jp * jp + kinetic - h * cos(a.p[1](0));
  }
  template <class T>
  Vec<T, 1> constraints(const Window<Se2Order3, T>& a, double h) const {
    return Vec<T, 1>((a.g[2].angle - 2.0 * a.g[1].angle + a.g[0].angle) / h);
  }
  template <class T>
  SE2::Element<T> connection(const Vec<T, 1>& p0, const Vec<T, 1>& p1) const {
    return {0.4 * (p1(0) - p0(0)), Eigen::Matrix<T, 2, 1>(T(0.0), T(0.0))};
  }
};

double quintic(const Eigen::Matrix<double, 6, 1>& c, double t) {
  double v = 0;
  for (int i = 5; i >= 0; --i) v = v * t + c(i);
  return v;
}
}  // namespace

TEST(HigherOrder, Order3FlowReproducesQuinticsExactly) {
  const double h = 0.05;
  const int N = 60;
  Eigen::Matrix<double, 6, 1> cp, cx, cy;
  cp << 0.3, -1.0, 0.5, 0.7, -0.4, 0.2;
  cx << 1.0, 0.5, -0.3, 0.2, 0.1, -0.05;
  cy << -0.5, 0.2, 0.4, -0.6, 0.3, 0.1;
  FlowState<Jerk> s;
  for (int i = 0; i < 6; ++i) s.p[i] = Vec<double, 1>(quintic(cp, i * h));
  for (int i = 0; i < 5; ++i)
    s.g[i] = Eigen::Vector2d(quintic(cx, (i + 1) * h) - quintic(cx, i * h), quintic(cy, (i + 1) * h) - quintic(cy, i * h));
  const auto res = DiscreteFlow<Jerk>(Jerk{}, h).run(s, N);
  ASSERT_TRUE(res.report.ok()) << res.report.message;
  const auto x = reconstruct_group(Jerk{}, res.trajectory, Eigen::Vector2d(quintic(cx, 0), quintic(cy, 0)));
  double err = 0, scale = 0;
  for (int n = 0; n <= N; ++n) {
    const double t = n * h;
    err = std::max({err, std::abs(res.trajectory.p[n](0) - quintic(cp, t)), std::abs(x[n](0) - quintic(cx, t)),
                    std::abs(x[n](1) - quintic(cy, t))});
    scale = std::max({scale, std::abs(quintic(cp, t)), std::abs(quintic(cx, t))});
  }
  std::printf("k = 3 quintic over %d steps: max error %.2e (scale %.2f)\n", N, err, scale);
  // A k = 3 recursion amplifies roundoff like N^5 eps: 60^5 * 2.2e-16 = 1.7e-7; any error in the
  // derived equations would show as O(1).
  EXPECT_LT(err, 1.7e-7 * scale);
}

TEST(HigherOrder, Order3OnSE2ConservesMomentumAndHasExactSensitivities) {
  const Se2Order3 problem;
  const double h = 0.05;
  FlowState<Se2Order3> s;
  for (int i = 0; i < 6; ++i) s.p[i] = Vec<double, 1>(0.2 + 0.3 * i * h + 0.1 * (i * h) * (i * h));
  for (int i = 0; i < 5; ++i) s.g[i] = {h * (0.7 + 0.01 * i), Eigen::Vector2d(h * 0.5, -h * 0.2 * (1 + 0.02 * i))};
  s.lam = {Vec<double, 1>(0.1), Vec<double, 1>(0.12), Vec<double, 1>(0.15)};
  const DiscreteFlow<Se2Order3> flow(problem, h);
  constexpr int ns = Dims<Se2Order3>::state;
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(ns, ns);
  const auto res = flow.run(s, 150, &I);
  ASSERT_TRUE(res.report.ok()) << res.report.message;
  const double drift = momentum_drift(problem, res.trajectory, SE2::identity<double>());
  std::printf("k = 3 on SE(2): relative momentum drift over 150 steps %.2e\n", drift);
  EXPECT_LE(drift, 1e-11);

  // Sensitivities after 20 steps against Richardson-extrapolated central differences.
  const int N = 25;
  const auto short_run = flow.run(s, N, &I);
  ASSERT_TRUE(short_run.report.ok());
  const auto final_state = short_run.trajectory.state(N - 2);
  auto central = [&](int j, double eps) {
    Vec<double, ns> e = Vec<double, ns>::Zero();
    e(j) = eps;
    const auto p = flow.run(retract(s, e), N), m = flow.run(retract(s, Vec<double, ns>(-e)), N);
    return Vec<double, ns>((state_difference(p.trajectory.state(N - 2), final_state) -
                            state_difference(m.trajectory.state(N - 2), final_state)) /
                           (2 * eps));
  };
  for (int j = 0; j < ns; ++j) {
    const Vec<double, ns> fd = (4 * central(j, 5e-6) - central(j, 1e-5)) / 3;
    EXPECT_LT((short_run.sensitivity.col(j) - fd).lpNorm<Eigen::Infinity>(),
              1e-7 * std::max(1.0, fd.lpNorm<Eigen::Infinity>()))
        << "column " << j;
  }
}
