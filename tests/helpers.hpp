// Initial data for the tests: the paper's systems started from continuous-looking data.
#pragma once

#include <lpshoot/problems/beanie.hpp>
#include <lpshoot/problems/electron.hpp>

#include <algorithm>
#include <cmath>

namespace lpshoot::test_support {

using problems::BeanieControl;
using problems::BeanieFree;
using problems::BeanieParameters;

// Free beanie from q(0) and q'(0): q_1 = q_0 + h q'(0).
inline FlowState<BeanieFree> beanie_free_initial(const BeanieParameters& par, const Eigen::Vector4d& q0,
                                                 const Eigen::Vector4d& v0, double h) {
  const Eigen::Vector4d q1 = q0 + h * v0;
  FlowState<BeanieFree> s;
  s.p = {Vec<double, 1>(q0(3)), Vec<double, 1>(q1(3))};
  s.g = {problems::beanie_increment(par, q0, q1)};
  return s;
}

// k = 2 beanie control: ψ_i = ψ(0) + ψ'(0) t_i + ψ''(0) t_i^2/2 for i = 0..3, g~_0 = (h Ω3, h Ω12), g~_1, g~_2 from the constraints
// chi(a_0) = chi(a_1) = 0 of the chosen variant, λ^0 and λ^1 given.
inline FlowState<BeanieControl> beanie_control_initial(const BeanieControl& b, const Eigen::Vector3d& psi_data,
                                                       const Eigen::Vector3d& Omega, const Eigen::Vector3d& lam0,
                                                       const Eigen::Vector3d& lam1, double h) {
  FlowState<BeanieControl> s;
  std::array<double, 4> psi;
  for (int i = 0; i < 4; ++i) {
    psi[i] = psi_data(0) + psi_data(1) * i * h + 0.5 * psi_data(2) * (i * h) * (i * h);
    s.p[i] = Vec<double, 1>(psi[i]);
  }
  s.g[0] = {h * Omega(2), h * Omega.head<2>()};
  for (int i = 1; i < 3; ++i) s.g[i] = b.next_increment(s.g[i - 1], psi[i] - psi[i - 1]);
  s.lam = {lam0, lam1};
  return s;
}

inline double max_abs_diff(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).lpNorm<Eigen::Infinity>();
}

}  // namespace lpshoot::test_support
