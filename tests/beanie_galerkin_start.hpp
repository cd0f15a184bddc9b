// A Galerkin beanie start for flow tests: the first interval of the guess of a well-posed problem,
// with small non-zero bubbles and multipliers.
#pragma once

#include <lpshoot/problems/beanie_bvp.hpp>

#include <cmath>

namespace lpshoot::test_support {

// The well-posed data of the beanie scene (examples/scenes/beanie.json): ψ from rest at 0 to rest
// at 1, g(0) = e, Ω12(0) = (0.5, 0.2), θ(T) = 1.
inline void beanie_scene_boundary(problems::BeanieBoundary& s, problems::BeanieBoundary& e) {
  s.psi = 0, s.psi_dot = 0, s.theta = 0, s.x = 0, s.y = 0, s.Omega1 = 0.5, s.Omega2 = 0.2;
  e.psi = 1, e.psi_dot = 0, e.theta = 1;
}

template <int S = 3>
Interval<problems::BeanieGalerkin<S>, double> beanie_interval_with_multipliers(const problems::BeanieModel& model,
                                                                               double T, int N) {
  using namespace problems;
  BeanieBoundary s, e;
  s.psi = 0.2, s.psi_dot = 0.4, s.theta = 0.1, s.x = 0, s.y = 0, s.Omega1 = 0.5, s.Omega2 = 0.2;
  e.psi = 1, e.psi_dot = 0, e.theta = 1;
  const auto bvp = beanie_galerkin_bvp<S>(model, T, N, s, e);
  Interval<BeanieGalerkin<S>, double> iv = beanie_galerkin_guess<S>(bvp, s, e).trajectory.intervals[0];
  for (int i = 0; i < BeanieGalerkin<S>::aux; ++i) iv.w(i) = 0.01 * std::sin(1.0 + i);  // bubbles and multipliers
  return iv;
}

}  // namespace lpshoot::test_support
