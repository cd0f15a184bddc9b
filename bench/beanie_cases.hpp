// The beanie control's paper-scheme state at step 2 and its Galerkin scheme's first interval,
// shared by the step benchmarks (bench_step, bench_galerkin_step, bench_ratios).
#pragma once

#include "beanie_galerkin_start.hpp"  // tests/

namespace lpshoot::bench {

inline problems::BeanieControl beanie_control() {
  problems::BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  return b;
}

// Smooth nodes, increments that satisfy the constraints, non-zero multipliers.
inline FlowState<problems::BeanieControl> beanie_state(const problems::BeanieControl& b, double h) {
  FlowState<problems::BeanieControl> s;
  for (int i = 0; i < 4; ++i) s.p[i] = Vec<double, 1>(0.5 + 0.8 * i * h - 0.25 * (i * h) * (i * h));
  s.g[0] = {0.6 * h, Eigen::Vector2d(0.8 * h, -0.3 * h)};
  for (int i = 1; i < 3; ++i) s.g[i] = b.next_increment(s.g[i - 1], s.p[i](0) - s.p[i - 1](0));
  s.lam = {Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(0.302, -0.199, 0.101)};
  return s;
}

inline problems::BeanieModel beanie_model() {
  problems::BeanieModel b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  return b;
}

// The first interval of the Galerkin guess of bench_galerkin_step and bench_ratios (N = 200).
template <int S>
Interval<problems::BeanieGalerkin<S>, double> beanie_galerkin_start(const problems::BeanieModel& model) {
  return test_support::beanie_interval_with_multipliers<S>(model, 2.0, 200);
}

}  // namespace lpshoot::bench
