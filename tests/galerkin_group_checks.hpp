// Checks of Galerkin steps with a group from interval Hessians (core/galerkin_group.hpp) and of
// the end nodes' rows (core/galerkin_end_rows.hpp) against nested duals, for any degree: shared by
// test_galerkin_group.cpp (degrees 3 and 4, the "core" label) and test_galerkin_order8.cpp
// (degree 5, kept out of the checked build: its nested duals take gigabytes to compile under the
// sanitizers).
#pragma once

#include "beanie_galerkin_start.hpp"

#include <lpshoot/core/galerkin_end_rows.hpp>
#include <lpshoot/problems/beanie_bvp.hpp>

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

namespace lpshoot::test_support {

// An interval with every coordinate generic: W away from the identity, non-zero increments,
// bubbles and multipliers.
template <class Sch>
Interval<Sch, double> generic_interval(const problems::BeanieModel& model, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Interval<Sch, double> iv = beanie_interval_with_multipliers<Sch::degree>(model, 2.0, 40);
  for (int a = 0; a < Sch::r; ++a) iv.x(a) += u(rng), iv.v(a) += u(rng), iv.X2(a) = u(rng), iv.V1(a) = u(rng);
  for (int a = 0; a < Sch::d; ++a) iv.Om(a) += u(rng), iv.O1(a) = u(rng);
  iv.W = SE2::exp<double>(Eigen::Vector3d(u(rng), u(rng), u(rng)));
  for (int a = 0; a < Sch::aux; ++a) iv.w(a) = 0.5 * u(rng);
  return iv;
}

// F and J with the state's columns from interval Hessians (with and without a carried state)
// against nested duals: equal to roundoff. A sign error in a bracket term or in A_r's group block
// shows as an O(1) relative difference.
template <int S>
void expect_same_step(double h) {
  using Sch = problems::BeanieGalerkin<S>;
  constexpr int nz = Sch::unknowns, ns = Sch::state;
  problems::BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  std::mt19937 rng(11);
  double worst = 0, bracket_part = 0;
  for (int trial = 0; trial < 5; ++trial) {
    const auto state = generic_interval<Sch>(model, rng), z = generic_interval<Sch>(model, rng);
    Vec<double, nz> F1, F2, F3;
    Eigen::Matrix<double, nz, nz + ns> J1, J2, J3;
    evaluate_galerkin_step_nested<Sch, nz + ns>(model, h, state, z, true, nullptr, F1, J1);
    evaluate_galerkin_step_group<Sch, nz + ns>(model, h, state, z, nullptr, F2, J2, nullptr);
    StepCarry<Sch> carry;
    carry.interval = group_interval_derivatives<Sch>(model, state, h);
    carry.valid = true;
    // The state's part of E_n from its gradient (group_left_rows) equals node_residual's.
    const Vec<double, Sch::variation> fixed = node_residual<Sch, double>(model, &state, nullptr, h);
    const Vec<double, Sch::variation> left_rows = group_left_rows<Sch>(carry.interval.gradient, h);
    evaluate_galerkin_step_group<Sch, nz + ns>(model, h, state, z, nullptr, F3, J3, &carry);
    const double fs = F1.cwiseAbs().maxCoeff(), js = J1.cwiseAbs().maxCoeff();
    worst = std::max({worst, (F1 - F2).cwiseAbs().maxCoeff() / fs, (J1 - J2).cwiseAbs().maxCoeff() / js,
                      (F1 - F3).cwiseAbs().maxCoeff() / fs, (J1 - J3).cwiseAbs().maxCoeff() / js});
    worst = std::max(worst, (fixed - left_rows).cwiseAbs().maxCoeff() / fs);
    // The step matrix alone (a step's Newton), given the state's part of E_n.
    Vec<double, nz> G1, G2;
    Eigen::Matrix<double, nz, nz> K1, K2;
    evaluate_galerkin_step_nested<Sch, nz>(model, h, state, z, false, &fixed, G1, K1);
    evaluate_galerkin_step_group<Sch, nz>(model, h, state, z, &fixed, G2, K2, nullptr);
    worst = std::max({worst, (G1 - G2).cwiseAbs().maxCoeff() / G1.cwiseAbs().maxCoeff(),
                      (K1 - K2).cwiseAbs().maxCoeff() / K1.cwiseAbs().maxCoeff()});
    // The residual alone (chord iterations: node, bubble and multiplier rows in one pass).
    const Vec<double, nz> R = galerkin_step_residual<Sch>(model, h, state, z, fixed);
    worst = std::max(worst, (G1 - R).cwiseAbs().maxCoeff() / G1.cwiseAbs().maxCoeff());
    // The bracket terms are really exercised: without them the η rows would differ.
    const Eigen::Matrix<double, Sch::d, Sch::d> B =
        bracket_form<SE2>(carry.interval.gradient.template segment<Sch::d>(Sch::W_off));
    bracket_part = std::max(bracket_part, 0.5 * B.cwiseAbs().maxCoeff() / js);
    // The carry now holds interval n's derivatives.
    const auto dr_expected = [&] {
      Interval<Sch, double> right = z;
      const auto b = next_interval_base(state, h);
      right.x = b.x, right.v = b.v, right.Om = b.Om;
      return group_interval_derivatives<Sch>(model, right, h);
    }();
    EXPECT_EQ(carry.interval.gradient, dr_expected.gradient);
  }
  std::printf("beanie degree %d, h = %g: interval Hessians vs nested duals, max relative difference %.2e "
              "(bracket terms %.2e of |J|)\n",
              S, h, worst, bracket_part);
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(bracket_part, 1e-6);
}

// galerkin_end_rows (natural conditions and the first interval's own rows, with derivatives in
// the interval's tangent coordinates) against nested duals over the whole tangent: node_residual
// and aux_residual of the interval seeded in every coordinate, multipliers included.
template <class Sch>
double end_rows_difference(const typename Sch::Model& model, const Interval<Sch, double>& iv, double h) {
  constexpr int nz = Sch::unknowns, ns = Sch::state, nv = Sch::variation, nm = multiplier_count<Sch>;
  using TD = Dual<double, ns>;
  Interval<Sch, TD> s = seeded_state<Sch, TD>(iv, h, 0);
  for (int c = 0; c < nm; ++c) s.w(Sch::multipliers(0) + c) = TD::variable(iv.w(Sch::multipliers(0) + c), ns - nm + c);
  double worst = 0;
  for (bool initial : {true, false}) {
    Vec<double, nz> R;
    Eigen::Matrix<double, nz, ns> J;
    const int rows = galerkin_end_rows<Sch>(model, iv, h, initial, R, J);
    EXPECT_EQ(rows, initial ? nz : nv);
    Vec<TD, nz> ref;
    ref.template head<nv>() = initial ? node_residual<Sch, TD>(model, nullptr, &s, h) : node_residual<Sch, TD>(model, &s, nullptr, h);
    if (initial) ref.template tail<Sch::aux>() = aux_residual<Sch, TD>(model, s, h);
    double rs = 0, js = 0, dr = 0, dj = 0;
    for (int i = 0; i < rows; ++i) {
      rs = std::max(rs, std::abs(ref(i).v)), dr = std::max(dr, std::abs(ref(i).v - R(i)));
      for (int c = 0; c < ns; ++c) js = std::max(js, std::abs(ref(i).d[c])), dj = std::max(dj, std::abs(ref(i).d[c] - J(i, c)));
    }
    if (rows < nz) {
      EXPECT_EQ(J.bottomRows(nz - rows).cwiseAbs().maxCoeff(), 0.0);
    }
    worst = std::max({worst, dr / rs, dj / js});
  }
  return worst;
}

template <int S>
void expect_same_beanie_end_rows(double h) {
  using Sch = problems::BeanieGalerkin<S>;
  problems::BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  std::mt19937 rng(17);
  double worst = 0;
  for (int trial = 0; trial < 5; ++trial) worst = std::max(worst, end_rows_difference<Sch>(model, generic_interval<Sch>(model, rng), h));
  std::printf("beanie degree %d, h = %g: end rows from the interval's Hessian vs nested duals, max relative difference %.2e\n",
              S, h, worst);
  EXPECT_LT(worst, 1e-12);
}

}  // namespace lpshoot::test_support
