// The engine's derived Galerkin 4 step (nested duals and the chain rule through the jet, Newton,
// implicit-function sensitivity) against the electron's step derived by hand
// (oracles/galerkin_electron.hpp): one step with its sensitivity, and a 200-step flow with the
// sensitivity of its last interval to its first.
#include "oracles/galerkin_electron.hpp"

#include <lpshoot/core/lpshoot.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <vector>
#include <limits>

using namespace lpshoot;
using problems::ElectronModel;
using Sch = Galerkin<ElectronModel, 3>;

namespace {

constexpr double kU = std::numeric_limits<double>::epsilon();

Interval<Sch, double> interval_of(const oracles::GalerkinElectronState& c) {
  Interval<Sch, double> iv;
  iv.x = c.segment<3>(Sch::x_off), iv.v = c.segment<3>(Sch::v_off);
  iv.X2 = c.segment<3>(Sch::X2_off), iv.V1 = c.segment<3>(Sch::V1_off);
  return iv;
}

Eigen::Matrix<double, 6, 1> increments(const Interval<Sch, double>& iv) {
  Eigen::Matrix<double, 6, 1> z;
  z << iv.X2, iv.V1;
  return z;
}

ElectronModel electron(double mass, double e_over_c, const Eigen::Vector3d& B, double potential) {
  ElectronModel e;
  e.mass = mass, e.e_over_c = e_over_c, e.B = B, e.potential = potential;
  return e;
}

}  // namespace

TEST(GalerkinOracle, ElectronStepAndSensitivityMatchHandDerivation) {
  const ElectronModel models[] = {electron(1.0, 1.0, {0, 0, 1}, 1.0), electron(0.7, 2.3, {0.3, -0.5, 1.1}, 0.4)};
  for (const ElectronModel& model : models) {
    for (double h : {0.003, 0.05, 0.4}) {
      for (int trial = 0; trial < 3; ++trial) {
        const oracles::GalerkinElectronState c = oracles::GalerkinElectronState::Random();
        oracles::GalerkinElectronMap Phi;
        const Eigen::Matrix<double, 6, 1> z_hand = oracles::electron_galerkin4_step(model, h, c, &Phi);

        NewtonOptions opt;
        opt.reuse_constant_matrix = false;  // the engine's own Newton on its derived equations
        Interval<Sch, double> z;
        const StepReport rep = solve_galerkin_step<Sch>(model, h, interval_of(c), 1, opt, z);
        ASSERT_EQ(rep.status, StepStatus::Converged) << rep.message;
        double kappa = 0;  // the engine's estimate for its (scaled) step matrix
        const Eigen::Matrix<double, 6, 12> dz =
            galerkin_step_sensitivity<Sch>(model, h, interval_of(c), z, nullptr, &kappa);

        // Both solve the same linear system, in different scalings: they agree to the step
        // matrix's conditioning, κ u relative to the size of the terms (|Φ| |c|).
        const double scale = Phi.lpNorm<Eigen::Infinity>() * c.lpNorm<Eigen::Infinity>();
        const double dz_err = (increments(z) - z_hand).lpNorm<Eigen::Infinity>();
        const double ds_err = (dz - Phi).lpNorm<Eigen::Infinity>() / Phi.lpNorm<Eigen::Infinity>();
        std::printf("h = %.3f: |z| %.2e, step %.1e, sensitivity %.1e (relative), κ %.1e\n", h,
                    z_hand.lpNorm<Eigen::Infinity>(), dz_err, ds_err, kappa);
        // Newton stops at |correction| ≤ 1e-12 (1 + |z|); roundoff in either solve is ~κ u.
        EXPECT_LT(dz_err, 1e-12 * (1 + z_hand.lpNorm<Eigen::Infinity>()) + 10 * kappa * kU * scale) << "h = " << h;
        EXPECT_LT(ds_err, 10 * kappa * kU) << "h = " << h;
      }
    }
  }
}

// A flow of the linear electron takes its affine path (one step map per flow, one correction per
// step); the hand flow applies Φ at every step. Over 200 steps both must give the same intervals
// and the same sensitivity of the last interval to the first (Φ composed with the node shift).
TEST(GalerkinOracle, ElectronFlowAndItsSensitivityMatchHandSteps) {
  const ElectronModel model = electron(1.0, 1.0, {0, 0, 1}, 1.0);
  const double h = 0.01;
  const int steps = 200;
  oracles::GalerkinElectronState c;
  c << 1, 0, 0.5, 0, 1, -0.2, 0.3, -0.1, 0.2, 0.05, 0.4, -0.3;
  const GalerkinFlow<Sch> flow(model, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Sch::state, Sch::state);
  const auto res = flow.run(interval_of(c), steps, &seed);
  ASSERT_TRUE(res.report.ok()) << res.report.message;

  const oracles::GalerkinElectronMap Phi = oracles::electron_galerkin4_step_map(model, h);
  Eigen::Matrix<double, 12, 12> shift = Eigen::Matrix<double, 12, 12>::Zero();  // interval n-1 → node n
  shift.block<3, 3>(0, 0).setIdentity(), shift.block<3, 3>(0, 3).diagonal().setConstant(h);
  shift.block<3, 3>(0, 6).diagonal().setConstant(h * h);
  shift.block<3, 3>(3, 3).setIdentity(), shift.block<3, 3>(3, 9).diagonal().setConstant(h);
  Eigen::Matrix<double, 12, 12> step = shift;  // the whole interval n from interval n-1
  step.bottomRows<6>() = Phi;
  // Powers of the hand step, for the roundoff bound below.
  std::vector<Eigen::Matrix<double, 12, 12>> power(steps + 1, Eigen::Matrix<double, 12, 12>::Identity());
  for (int k = 1; k <= steps; ++k) power[k] = step * power[k - 1];
  const auto norm = [](const auto& A) { return A.template lpNorm<Eigen::Infinity>(); };
  double traj_err = 0, traj_bound = 0;
  for (int n = 1; n <= steps; ++n) {
    const oracles::GalerkinElectronState s = power[n] * c;
    const auto& iv = res.trajectory.intervals[n];
    oracles::GalerkinElectronState e;
    e << iv.x, iv.v, iv.X2, iv.V1;
    // A relative error δ in each step's map, carried to step n: Σ_k |step^(n-k)| δ |step| |s_(k-1)|.
    double carried = 0;
    for (int k = 1; k <= n; ++k) carried += norm(power[n - k]) * norm(step) * norm(power[k - 1] * c);
    traj_err = std::max(traj_err, (e - s).lpNorm<Eigen::Infinity>() / carried);
    traj_bound = std::max(traj_bound, carried);
  }
  double carried = 0;
  for (int k = 1; k <= steps; ++k) carried += norm(power[steps - k]) * norm(step) * norm(power[k - 1]);
  const double sens_err = norm(res.sensitivity - power[steps]) / carried;
  std::printf("carried roundoff per unit δ relative to the sensitivity: %.1e\n", carried / norm(power[steps]));
  std::printf("200 steps, error / (carried roundoff per unit δ): intervals %.1e, sensitivity %.1e\n", traj_err,
              sens_err);
  // δ: each step's map (the engine's, factored once per flow, and Φ) agrees to ~κ u ≈ 1e-14 (the
  // test above); 1e-13 leaves a factor 10. A wrong map, node shift or seed is off by O(h) or more.
  EXPECT_LT(traj_err, 1e-13);
  EXPECT_LT(sens_err, 1e-13);
}
