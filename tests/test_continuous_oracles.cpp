// The continuous-time oracles of METHOD.md §6.1 (electron, exact matrix exponential) and §6.2
// (beanie shape, Newton shooting): boundary data, the optimality conditions, costs by independent
// quadrature, and optimality against other admissible trajectories.
#include "oracles/continuous.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

using namespace lpshoot;
using oracles::BeanieOptimum;
using oracles::ElectronOptimum;
using problems::BeanieParameters;
using problems::Electron;

namespace {

// ∫_0^T f by composite 8-point Gauss–Legendre (nodes from Newton on P_8).
double gauss_legendre(const std::function<double(double)>& f, double T, int panels) {
  constexpr int n = 8;
  static const auto rule = [] {
    std::array<std::array<double, 2>, n> r{};
    for (int i = 0; i < n; ++i) {
      double x = std::cos(std::acos(-1.0) * (i + 0.75) / (n + 0.5)), dp = 0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1, p1 = x;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (x * p1 - p0) / (x * x - 1);
        x -= p1 / dp;
      }
      r[i] = {x, 2 / ((1 - x * x) * dp * dp)};
    }
    return r;
  }();
  const double h = T / panels;
  double sum = 0;
  for (int p = 0; p < panels; ++p)
    for (const auto& [x, w] : rule) sum += 0.5 * h * w * f(h * (p + 0.5 * (x + 1)));
  return sum;
}

// ---------------------------------------------------------------- electron

struct ElectronCase {
  Electron e;
  double T;
  Eigen::Vector3d x0, v0, xT, vT;
};

ElectronCase paper_case() {  // B = (0, 0, Bz), κ = 1 (METHOD.md §6.1), m ≠ 1 and ω ≠ 1
  ElectronCase c;
  c.e.mass = 1.3;
  c.e.e_over_c = 0.7;
  c.e.B = Eigen::Vector3d(0, 0, 1.5);
  c.e.potential = 1.0;
  c.T = 2.0;
  c.x0 = {1.0, 0.0, 0.5};
  c.v0 = {0.0, 1.0, -0.2};
  c.xT = {-0.3, 0.8, 0.1};
  c.vT = {0.2, -0.5, 0.4};
  return c;
}

ElectronCase general_case() {  // oblique B, κ ≠ 1
  ElectronCase c = paper_case();
  c.e.mass = 0.8;
  c.e.e_over_c = 1.1;
  c.e.B = Eigen::Vector3d(0.4, -0.9, 1.2);
  c.e.potential = 0.6;
  c.T = 1.7;
  return c;
}

ElectronOptimum solve(const ElectronCase& c) { return oracles::electron_exact_optimum(c.e, c.T, c.x0, c.v0, c.xT, c.vT); }

// d^k x/dt^k at t, from y^(k) = A^k y (x is the first block of y).
Eigen::Vector3d deriv(const ElectronOptimum& o, double t, int k) {
  Eigen::Matrix<double, 12, 1> y = o.state(t);
  for (int i = 0; i < k; ++i) y = o.A * y;
  return y.head<3>();
}

// The problem's control u = m x'' + 2κ x − (e/c) x' × B (electron.hpp, continuous form).
Eigen::Vector3d control_of(const Electron& e, const Eigen::Vector3d& x, const Eigen::Vector3d& v,
                           const Eigen::Vector3d& a) {
  return e.mass * a + 2 * e.potential * x - e.e_over_c * v.cross(e.B);
}

TEST(ContinuousElectron, HitsBoundaryDataAndControlMatchesDefinition) {
  for (const ElectronCase& c : {paper_case(), general_case()}) {
    const ElectronOptimum o = solve(c);
    EXPECT_LT((o.position(0) - c.x0).norm(), 1e-14);
    EXPECT_LT((o.velocity(0) - c.v0).norm(), 1e-14);
    EXPECT_LT((o.position(c.T) - c.xT).norm(), 1e-12);
    EXPECT_LT((o.velocity(c.T) - c.vT).norm(), 1e-12);
    for (double t : {0.0, 0.3, 0.9, c.T}) {
      const Eigen::Vector3d u = control_of(c.e, deriv(o, t, 0), deriv(o, t, 1), deriv(o, t, 2));
      EXPECT_LT((o.control(t) - u).norm(), 1e-12 * (1 + u.norm())) << "t = " << t;
    }
  }
}

// METHOD.md §6.1, (63) corrected, for B = (0, 0, Bz) and φ = |x|^2.
TEST(ContinuousElectron, SatisfiesCorrected63) {
  const ElectronCase c = paper_case();
  const ElectronOptimum o = solve(c);
  const double m = c.e.mass, w = c.e.e_over_c * c.e.B(2) / m;
  for (double t : {0.0, 0.37, 1.1, 1.64, c.T}) {
    std::array<Eigen::Vector3d, 5> d;
    for (int k = 0; k < 5; ++k) d[k] = deriv(o, t, k);
    const Eigen::Vector3d rhs(
        2 * w * d[3](1) + (w * w - 4 / m) * d[2](0) + (4 * w / m) * d[1](1) - 4 * d[0](0) / (m * m),
        -2 * w * d[3](0) + (w * w - 4 / m) * d[2](1) - (4 * w / m) * d[1](0) - 4 * d[0](1) / (m * m),
        -(4 / m) * d[2](2) - 4 * d[0](2) / (m * m));
    const double scale = d[4].norm() + d[3].norm() + d[2].norm() + d[1].norm() + d[0].norm();
    EXPECT_LT((d[4] - rhs).norm(), 1e-13 * scale) << "t = " << t;
    EXPECT_GT(d[4].norm(), 0.1);  // not trivially zero
  }
}

// cost = ½ ∫ |u|^2 by quadrature; a perturbation δ = t^2 (T − t)^2 a (zero with δ' at both
// ends) has zero first variation and raises the cost by exactly ½ ∫ |Lδ|^2.
TEST(ContinuousElectron, CostAndOptimality) {
  for (const ElectronCase& c : {paper_case(), general_case()}) {
    const ElectronOptimum o = solve(c);
    const double T = c.T;
    const int panels = 40;
    const double quad = gauss_legendre([&](double t) { return 0.5 * o.control(t).squaredNorm(); }, T, panels);
    EXPECT_NEAR(o.cost, quad, 1e-13 * quad);
    EXPECT_GT(o.cost, 0.1);

    for (const Eigen::Vector3d& a : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0.3, -0.7, 0.5)}) {
      auto Ldelta = [&](double t) {  // control of the perturbation alone (u is linear in x)
        const double q = t * (T - t), dq = T - 2 * t;
        return control_of(c.e, q * q * a, 2 * q * dq * a, (2 * dq * dq - 4 * q) * a);
      };
      const double first = gauss_legendre([&](double t) { return o.control(t).dot(Ldelta(t)); }, T, panels);
      const double second = gauss_legendre([&](double t) { return 0.5 * Ldelta(t).squaredNorm(); }, T, panels);
      const double perturbed =
          gauss_legendre([&](double t) { return 0.5 * (o.control(t) + Ldelta(t)).squaredNorm(); }, T, panels);
      EXPECT_LT(std::abs(first), 1e-12 * std::sqrt(2 * o.cost * 2 * second));
      EXPECT_GT(perturbed, o.cost + 0.01);
      EXPECT_NEAR(perturbed - o.cost, second, 1e-12 * perturbed);
    }
  }
}

// ---------------------------------------------------------------- beanie

std::vector<double> linspace(double T, int n) {
  std::vector<double> t(n + 1);
  for (int i = 0; i <= n; ++i) t[i] = T * i / n;
  t[n] = T;
  return t;
}

// With V = 0 and rest-to-rest data the optimum is the cubic (METHOD.md §6.2), J = 6 μ^2 Δψ^2/T^3.
TEST(ContinuousBeanie, CubicWithoutPotential) {
  BeanieParameters par;
  par.I1 = 1.0;
  par.I2 = 2.0;
  par.amplitude = 0.0;
  const double mu = par.mu(), T = 1.5, p0 = 0.3, p1 = 1.1, D = p1 - p0;
  const BeanieOptimum r = oracles::beanie_continuous_optimum(par, T, p0, 0.0, p1, 0.0, linspace(T, 30));
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LE(r.iterations, 1);
  EXPECT_NEAR(r.cost, 6 * mu * mu * D * D / (T * T * T), 1e-10 * r.cost);
  EXPECT_NEAR(r.u0, 6 * mu * D / (T * T), 1e-10);
  EXPECT_NEAR(r.du0, -12 * mu * D / (T * T * T), 1e-10);
  for (std::size_t i = 0; i < r.times.size(); ++i) {
    const double s = r.times[i] / T;
    EXPECT_NEAR(r.psi[i], p0 + D * (3 * s * s - 2 * s * s * s), 1e-10);
    EXPECT_NEAR(r.dpsi[i], D * (6 * s - 6 * s * s) / T, 1e-10);
    EXPECT_NEAR(r.u[i], mu * D * (6 - 12 * s) / (T * T), 1e-10);
  }
}

// With V = 1 − cos ψ: boundary data, the state and costate equations by finite differences of the
// dense samples, the cost by Simpson, a zero first variation, and a lower cost than the cubic's.
TEST(ContinuousBeanie, PotentialShooting) {
  struct Case {
    double T, p0, d0, p1, d1;
  };
  for (const Case& c : {Case{2.0, 0.0, 0.0, 1.0, 0.0}, Case{1.5, -0.5, 0.8, 2.0, -0.3}}) {
    BeanieParameters par;  // I1 = I2 = 1: μ = 0.5
    par.amplitude = 1.0;
    const double mu = par.mu(), T = c.T;
    const int n = 2000;
    const double h = T / n;
    const BeanieOptimum r = oracles::beanie_continuous_optimum(par, T, c.p0, c.d0, c.p1, c.d1, linspace(T, n));
    ASSERT_TRUE(r.converged) << r.message;
    ASSERT_EQ(r.psi.size(), std::size_t(n + 1));
    EXPECT_LE(r.iterations, 10);
    EXPECT_NEAR(r.psi.front(), c.p0, 1e-14);
    EXPECT_NEAR(r.dpsi.front(), c.d0, 1e-14);
    EXPECT_NEAR(r.u.front(), r.u0, 1e-14);
    EXPECT_NEAR(r.psi.back(), c.p1, 1e-10);
    EXPECT_NEAR(r.dpsi.back(), c.d1, 1e-10);

    // Central differences (error ~h^2/12 · 4th derivative ≈ 1e-7) of ψ and u.
    double state_res = 0, costate_res = 0, velocity_res = 0;
    for (int i = 1; i < n; ++i) {
      const double psi_dd = (r.psi[i + 1] - 2 * r.psi[i] + r.psi[i - 1]) / (h * h);
      const double u_dd = (r.u[i + 1] - 2 * r.u[i] + r.u[i - 1]) / (h * h);
      state_res = std::max(state_res, std::abs(r.u[i] - (mu * psi_dd + std::sin(r.psi[i]))));
      costate_res = std::max(costate_res, std::abs(mu * u_dd + std::cos(r.psi[i]) * r.u[i]));
      velocity_res = std::max(velocity_res, std::abs(r.dpsi[i] - (r.psi[i + 1] - r.psi[i - 1]) / (2 * h)));
    }
    EXPECT_LT(state_res, 1e-5);
    EXPECT_LT(costate_res, 1e-5);
    EXPECT_LT(velocity_res, 1e-5);

    // Simpson on the samples: ½ ∫ u^2 and the first variation ∫ u (μ δ'' + V''(ψ) δ), δ = t^2 (T − t)^2.
    double simpson_cost = 0, first = 0, second = 0;
    for (int i = 0; i <= n; ++i) {
      const double w = (i == 0 || i == n) ? h / 3 : (i % 2 ? 4 * h / 3 : 2 * h / 3), t = r.times[i];
      const double q = t * (T - t), dq = T - 2 * t, Ld = mu * (2 * dq * dq - 4 * q) + std::cos(r.psi[i]) * q * q;
      simpson_cost += w * 0.5 * r.u[i] * r.u[i];
      first += w * r.u[i] * Ld;
      second += w * Ld * Ld;
    }
    EXPECT_NEAR(simpson_cost, r.cost, 1e-10 * r.cost);
    EXPECT_LT(std::abs(first), 1e-9 * std::sqrt(2 * r.cost * second));

    // The cubic Hermite interpolant of the same data is admissible and costs more.
    const double gap = c.p1 - c.p0 - c.d0 * T, ddv = (c.d1 - c.d0) * T;
    const double c2 = (3 * gap - ddv) / (T * T), c3 = (ddv - 2 * gap) / (T * T * T);
    const double cubic_cost = gauss_legendre(
        [&](double t) {
          const double u = mu * (2 * c2 + 6 * c3 * t) + std::sin(c.p0 + c.d0 * t + c2 * t * t + c3 * t * t * t);
          return 0.5 * u * u;
        },
        T, 20);
    EXPECT_LT(r.cost, cubic_cost);
    RecordProperty("cost_vs_cubic", std::to_string(r.cost) + " < " + std::to_string(cubic_cost));
  }
}

TEST(ContinuousBeanie, RejectsBadTimes) {
  BeanieParameters par;
  EXPECT_THROW(oracles::beanie_continuous_optimum(par, 1.0, 0, 0, 1, 0, {0.5, 0.2}), std::invalid_argument);
  EXPECT_THROW(oracles::beanie_continuous_optimum(par, 1.0, 0, 0, 1, 0, {0.5, 1.5}), std::invalid_argument);
  EXPECT_THROW(oracles::beanie_continuous_optimum(par, 0.0, 0, 0, 1, 0, {}), std::invalid_argument);
}

}  // namespace

// Long horizons with an unstable potential (issue 14): expm(A T) grows like e^{√2 T} (1e30 at
// T = 50), so one exponential over [0, T] cannot hit the end data; the piecewise oracle must hit
// all four boundary values, satisfy y' = A y across every piece joint, and be self-consistent
// between a run on T and the same problem restarted from its own state at T/2.
TEST(ContinuousElectron, LongUnstableHorizonsAreComputedStably) {
  for (double T : {50.0, 100.0}) {
    ElectronCase c = paper_case();
    c.e.potential = -1.0;
    c.T = T;
    const ElectronOptimum o = solve(c);
    EXPECT_LT(o.residual, 1e-12) << "T = " << T;
    EXPECT_LT((o.position(0) - c.x0).norm(), 1e-9);
    EXPECT_LT((o.velocity(0) - c.v0).norm(), 1e-9);
    EXPECT_LT((o.position(T) - c.xT).norm(), 1e-9) << "T = " << T;
    EXPECT_LT((o.velocity(T) - c.vT).norm(), 1e-9) << "T = " << T;
    // The second half, solved as its own problem from the state at T/2, is the same motion.
    ElectronCase half = c;
    half.T = T / 2;
    half.x0 = o.position(T / 2);
    half.v0 = o.velocity(T / 2);
    const ElectronOptimum h = solve(half);
    for (double s : {0.1 * T, 0.25 * T, 0.4 * T})
      EXPECT_LT((h.position(s) - o.position(T / 2 + s)).norm(), 1e-8 * (1 + o.position(T / 2 + s).norm()))
          << "T = " << T << ", s = " << s;
    EXPECT_GT(o.cost, 0);
    EXPECT_TRUE(std::isfinite(o.cost));
  }
}
