// The engine's derived Galerkin 4 and 6 steps (nested duals and the chain rule through the jet,
// Newton, implicit-function sensitivity) against the electron's steps derived by hand
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
template <int S>
using Sch = Galerkin<ElectronModel, S>;

namespace {

constexpr double kU = std::numeric_limits<double>::epsilon();

// The hand oracle of each degree: its interval (x, v, X2, V1, [bubble]) and step map.
template <int S>
struct Hand;
template <>
struct Hand<3> {
  using State = oracles::GalerkinElectronState;
  static oracles::GalerkinElectronMap map(const ElectronModel& m, double h) { return oracles::electron_galerkin4_step_map(m, h); }
};
template <>
struct Hand<4> {
  using State = oracles::GalerkinElectron6State;
  static oracles::GalerkinElectron6Map map(const ElectronModel& m, double h) { return oracles::electron_galerkin6_step_map(m, h); }
};

template <int S>
Interval<Sch<S>, double> interval_of(const typename Hand<S>::State& c) {
  using Sc = Sch<S>;
  Interval<Sc, double> iv;
  iv.x = c.template segment<3>(Sc::x_off), iv.v = c.template segment<3>(Sc::v_off);
  iv.X2 = c.template segment<3>(Sc::X2_off), iv.V1 = c.template segment<3>(Sc::V1_off);
  iv.w = c.template segment<Sc::aux>(Sc::aux_off);
  return iv;
}

template <int S>
Eigen::Matrix<double, Sch<S>::unknowns, 1> increments(const Interval<Sch<S>, double>& iv) {
  Eigen::Matrix<double, Sch<S>::unknowns, 1> z;
  z << iv.X2, iv.V1, iv.w;
  return z;
}

ElectronModel electron(double mass, double e_over_c, const Eigen::Vector3d& B, double potential) {
  ElectronModel e;
  e.mass = mass, e.e_over_c = e_over_c, e.B = B, e.potential = potential;
  return e;
}

template <int S>
void check_step_and_sensitivity() {
  const ElectronModel models[] = {electron(1.0, 1.0, {0, 0, 1}, 1.0), electron(0.7, 2.3, {0.3, -0.5, 1.1}, 0.4)};
  for (const ElectronModel& model : models) {
    for (double h : {0.003, 0.05, 0.4}) {
      for (int trial = 0; trial < 3; ++trial) {
        const typename Hand<S>::State c = Hand<S>::State::Random();
        const auto Phi = Hand<S>::map(model, h);
        const Eigen::Matrix<double, Sch<S>::unknowns, 1> z_hand = Phi * c;

        NewtonOptions opt;
        opt.reuse_constant_matrix = false;  // the engine's own Newton on its derived equations
        Interval<Sch<S>, double> z;
        const StepReport rep = solve_galerkin_step<Sch<S>>(model, h, interval_of<S>(c), 1, opt, z);
        ASSERT_EQ(rep.status, StepStatus::Converged) << rep.message;
        double kappa = 0;  // the engine's estimate for its (scaled) step matrix
        const Eigen::Matrix<double, Sch<S>::unknowns, Sch<S>::state> dz =
            galerkin_step_sensitivity<Sch<S>>(model, h, interval_of<S>(c), z, nullptr, &kappa);

        // Both solve the same linear system, in different scalings: they agree to the step
        // matrix's conditioning, κ u relative to the size of the terms (|Φ| |c|).
        const double scale = Phi.template lpNorm<Eigen::Infinity>() * c.template lpNorm<Eigen::Infinity>();
        const double dz_err = (increments<S>(z) - z_hand).template lpNorm<Eigen::Infinity>();
        const double ds_err = (dz - Phi).template lpNorm<Eigen::Infinity>() / Phi.template lpNorm<Eigen::Infinity>();
        std::printf("S = %d, h = %.3f: |z| %.2e, step %.1e, sensitivity %.1e (relative), κ %.1e\n", S, h,
                    z_hand.template lpNorm<Eigen::Infinity>(), dz_err, ds_err, kappa);
        // Newton stops at |correction| ≤ 1e-12 (1 + |z|); roundoff in either solve is ~κ u.
        EXPECT_LT(dz_err, 1e-12 * (1 + z_hand.template lpNorm<Eigen::Infinity>()) + 10 * kappa * kU * scale) << "h = " << h;
        EXPECT_LT(ds_err, 10 * kappa * kU) << "h = " << h;
      }
    }
  }
}

}  // namespace

TEST(GalerkinOracle, ElectronStepAndSensitivityMatchHandDerivation) {
  check_step_and_sensitivity<3>();
  check_step_and_sensitivity<4>();
}

// A flow of the linear electron takes its affine path (one step map per flow, one correction per
// step); the hand flow applies Φ at every step. Over 200 steps both must give the same intervals
// and the same sensitivity of the last interval to the first (Φ composed with the node shift).
namespace {
template <int S>
void check_flow() {
  using Sc = Sch<S>;
  constexpr int ns = Sc::state, nz = Sc::unknowns;
  using Square = Eigen::Matrix<double, ns, ns>;
  const ElectronModel model = electron(1.0, 1.0, {0, 0, 1}, 1.0);
  const double h = 0.01;
  const int steps = 200;
  typename Hand<S>::State c;
  c.template head<12>() << 1, 0, 0.5, 0, 1, -0.2, 0.3, -0.1, 0.2, 0.05, 0.4, -0.3;
  if constexpr (S == 4) c.template tail<3>() << 0.01, -0.02, 0.03;  // the bubble
  const GalerkinFlow<Sc> flow(model, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(ns, ns);
  const auto res = flow.run(interval_of<S>(c), steps, &seed);
  ASSERT_TRUE(res.report.ok()) << res.report.message;

  const auto Phi = Hand<S>::map(model, h);
  Square shift = Square::Zero();  // interval n-1 → node n
  shift.template block<3, 3>(0, 0).setIdentity(), shift.template block<3, 3>(0, 3).diagonal().setConstant(h);
  shift.template block<3, 3>(0, 6).diagonal().setConstant(h * h);
  shift.template block<3, 3>(3, 3).setIdentity(), shift.template block<3, 3>(3, 9).diagonal().setConstant(h);
  Square step = shift;  // the whole interval n from interval n-1
  step.template bottomRows<nz>() = Phi;
  // Powers of the hand step, for the roundoff bound below.
  std::vector<Square> power(steps + 1, Square::Identity());
  for (int k = 1; k <= steps; ++k) power[k] = step * power[k - 1];
  const auto norm = [](const auto& A) { return A.template lpNorm<Eigen::Infinity>(); };
  double traj_err = 0, traj_bound = 0;
  for (int n = 1; n <= steps; ++n) {
    const typename Hand<S>::State s = power[n] * c;
    const auto& iv = res.trajectory.intervals[n];
    typename Hand<S>::State e;
    e << iv.x, iv.v, iv.X2, iv.V1, iv.w;
    // A relative error δ in each step's map, carried to step n: Σ_k |step^(n-k)| δ |step| |s_(k-1)|.
    double carried = 0;
    for (int k = 1; k <= n; ++k) carried += norm(power[n - k]) * norm(step) * norm(power[k - 1] * c);
    traj_err = std::max(traj_err, (e - s).template lpNorm<Eigen::Infinity>() / carried);
    traj_bound = std::max(traj_bound, carried);
  }
  double carried = 0;
  for (int k = 1; k <= steps; ++k) carried += norm(power[steps - k]) * norm(step) * norm(power[k - 1]);
  const double sens_err = norm(res.sensitivity - power[steps]) / carried;
  std::printf("carried roundoff per unit δ relative to the sensitivity: %.1e\n", carried / norm(power[steps]));
  std::printf("S = %d, 200 steps, error / (carried roundoff per unit δ): intervals %.1e, sensitivity %.1e\n", S,
              traj_err, sens_err);
  // δ: each step's map (the engine's, factored once per flow, and Φ) agrees to ~κ u ≈ 1e-14 (the
  // test above); 1e-13 leaves a factor 10. A wrong map, node shift or seed is off by O(h) or more.
  EXPECT_LT(traj_err, 1e-13);
  EXPECT_LT(sens_err, 1e-13);
}
}  // namespace

TEST(GalerkinOracle, ElectronFlowAndItsSensitivityMatchHandSteps) {
  check_flow<3>();
  check_flow<4>();
}
