// Checks of the Galerkin beanie (SE(2) with constraints) for any degree S, shared by
// test_galerkin.cpp (degrees 3 and 4, the "core" label) and test_galerkin_order8.cpp (degree 5,
// kept out of the checked build: its instances take gigabytes to compile under the sanitizers):
// the discrete momentum map along a flow with non-zero multipliers, the flow's sensitivities and
// the shooting Jacobian against finite differences.
#pragma once

#include "beanie_galerkin_start.hpp"
#include "jacobian_check.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

namespace lpshoot::test_support {

// The discrete momentum map (METHOD.md §4) stays constant along a flow whose multipliers are
// non-zero.
template <int S>
void check_momentum_conserved() {
  using BG = problems::BeanieGalerkin<S>;
  problems::BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  const double h = 0.01;
  const auto start = beanie_interval_with_multipliers<S>(model, 6.0, 600);
  const SE2::Element<double> g0{0.3, Eigen::Vector2d(0.5, -0.2)};
  // J is conserved up to the steps' Newton tolerance (METHOD.md §4): take it near roundoff. The
  // rounding left is intrinsic: the momentum-matching equations cancel terms of size |λ|/h, so the
  // drift grows like u·|λ|·√n/h (measured 3.8e-13 relative here, 100 steps, h = 0.01, |λ| ≈ 3).
  NewtonOptions tight;
  tight.step_tolerance = 1e-13;
  const auto run = GalerkinFlow<BG>(model, h, tight).run(start, 100, nullptr, g0);
  ASSERT_TRUE(run.report.ok()) << run.report.message;
  const auto J = galerkin_spatial_momentum(model, run.trajectory);
  double drift = 0, lam = 0;
  for (const auto& Jn : J) drift = std::max(drift, (Jn - J.front()).template lpNorm<Eigen::Infinity>());
  for (const auto& iv : run.trajectory.intervals) lam = std::max(lam, iv.w.template lpNorm<Eigen::Infinity>());
  const double relative = drift / std::max(1.0, J.front().template lpNorm<Eigen::Infinity>());
  std::printf("degree %d, 100 steps, max |lambda| %.3g, |J_0| %.3g, relative drift %.2e\n", S, lam,
              J.front().template lpNorm<Eigen::Infinity>(), relative);
  EXPECT_GT(lam, 1e-2);  // the multipliers really are non-zero
  EXPECT_LT(relative, 1e-12);
}

// The flow's sensitivities (implicit function theorem on the step, multiplier columns as first
// derivatives of the constraint terms, galerkin_step.hpp) against central differences.
template <int S>
void check_flow_sensitivity() {
  using BG = problems::BeanieGalerkin<S>;
  problems::BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  const double h = 0.05;
  const auto start = beanie_interval_with_multipliers<S>(model, 2.0, 40);
  const SE2::Element<double> g0{0.3, Eigen::Vector2d(0.5, -0.2)};
  NewtonOptions tight;
  tight.step_tolerance = 1e-13;
  const GalerkinFlow<BG> flow(model, h, tight);
  constexpr int ns = BG::state, n = ns + BG::d;
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(n, n);
  const int steps = 20;
  const auto base = flow.run(start, steps, &seed, g0);
  ASSERT_TRUE(base.report.ok()) << base.report.message;
  // Central differences: truncation ~ eps² |d³|, noise ~ (Newton tolerance 1e-13 x amplification) / eps.
  const double eps = 1e-5;
  double worst = 0;
  for (int j = 0; j < n; ++j) {
    auto end_after = [&](double s) {
      Vec<double, n> delta = Vec<double, n>::Zero();
      delta(j) = s;
      const auto iv = retract<BG>(start, Vec<double, ns>(delta.template head<ns>()), h);
      const SE2::Element<double> g = SE2::compose(g0, SE2::exp<double>(Eigen::Vector3d(delta.template tail<3>())));
      const auto r = flow.run(iv, steps, nullptr, g);
      EXPECT_TRUE(r.report.ok());
      Eigen::VectorXd out(n);
      out.head(ns) = state_difference(r.trajectory.intervals.back(), base.trajectory.intervals.back(), h);
      out.tail(3) = SE2::log(SE2::compose(SE2::inverse(base.g_last), r.g_last));
      return out;
    };
    const Eigen::VectorXd fd = (end_after(eps) - end_after(-eps)) / (2 * eps);
    worst = std::max(worst, (base.sensitivity.col(j) - fd).template lpNorm<Eigen::Infinity>() / std::max(1.0, fd.template lpNorm<Eigen::Infinity>()));
  }
  std::printf("beanie Galerkin flow (degree %d), %d steps: max relative sensitivity error %.2e\n", S, steps, worst);
  EXPECT_LT(worst, 1e-6);
}

// The shooting Jacobian (flows' sensitivities, continuity, and the boundary rows from the end
// intervals' Hessians, galerkin_end_rows) against central differences.
template <int S>
void check_shooting_jacobian() {
  using Sch = problems::BeanieGalerkin<S>;
  problems::BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  problems::BeanieBoundary s, e;
  s.psi = 0.1, s.psi_dot = 0.3, s.theta = 0.2, s.x = 0.5, s.y = -0.3, s.Omega1 = 0.5, s.Omega2 = 0.2;
  e.psi = 1.0, e.psi_dot = -0.2, e.theta = 1.4, e.x = 1.0;  // x(T) fixed too: group natural + fixed mix
  const int N = 30;
  const auto bvp = problems::beanie_galerkin_bvp<S>(model, 1.5, N, s, e);
  const auto guess = problems::beanie_galerkin_guess<S>(bvp, s, e);
  for (int segs : {1, 3}) {
    std::vector<int> starts;
    for (int i = 0; i <= segs; ++i) starts.push_back((N - 1) * i / segs);
    const auto refs = GalerkinScheme<Sch>::states(bvp, guess, std::vector<int>(starts.begin(), starts.end() - 1));
    NewtonOptions tight;
    tight.step_tolerance = 1e-13;
    detail::ShootingSystem<Sch> sys(bvp, refs, starts, tight, 1);
    const Eigen::VectorXd x = random_point(sys.size());
    SparseJacobian Js;
    ASSERT_TRUE(sys.jacobian(x, Js));
    const Eigen::MatrixXd J(Js);
    // Richardson-extrapolated central differences (truncation O(eps^4), noise ~1e-13/eps).
    const double worst = richardson_jacobian_error(sys, x, J, 1e-5);
    std::printf("degree %d, segments %d: %d unknowns, max relative Jacobian error %.2e\n", S, segs, sys.size(), worst);
    EXPECT_LT(worst, 1e-6);
  }
}

}  // namespace lpshoot::test_support
