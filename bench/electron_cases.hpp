// The electron's first Galerkin interval of its guess, shared by the step benchmarks
// (bench_galerkin_step, bench_ratios).
#pragma once

#include <lpshoot/problems/electron_bvp.hpp>

namespace lpshoot::bench {

// The first interval of the electron's Galerkin guess (T = 2, N = 200).
template <int S>
Interval<problems::ElectronGalerkin<S>, double> electron_start(const problems::ElectronModel& model) {
  problems::ElectronBoundary a, b;
  a.position = {1, 0, 0.5}, a.velocity = {0, 1, 0}, b.position = {0, 1, -0.5}, b.velocity = {-1, 0, 0.2};
  const auto bvp = problems::electron_galerkin_bvp<S>(model, 2.0, 200, a, b);
  return problems::electron_galerkin_guess<S>(bvp, a, b).trajectory.intervals[0];
}

}  // namespace lpshoot::bench
