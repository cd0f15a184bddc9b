// `solve` for the beanie optimal-control scene on the Galerkin schemes of order 4 and 6
// (METHOD.md §9): node data ψ, ψ', Ω and g; the shape control u = μ ψ'' + V'(ψ) at each node from
// the discrete Legendre transform (node_jet); the scheme's momentum map J (conserved to roundoff)
// and the mechanical momentum P of the free beanie along the motion (conserved to the scheme's
// order: its equations are the constraints, imposed at the Gauss points).
#pragma once

#include "run_common.hpp"

namespace lpshoot::app {


// Columns PREFIX1..3 and PREFIX_drift of momenta given at nodes 0..n_last (empty cells after);
// returns the max drift.
inline double add_momentum(const std::vector<Eigen::Vector3d>& J, int N, const std::string& prefix, Table& table,
                    std::vector<double>& J0) {
  std::vector<std::vector<double>> comp(3, std::vector<double>(N + 1, nan()));
  std::vector<double> drift(N + 1, nan());
  double worst = 0;
  for (size_t n = 0; n < J.size(); ++n) {
    for (int a = 0; a < 3; ++a) comp[a][n] = J[n](a);
    drift[n] = (J[n] - J.front()).lpNorm<Eigen::Infinity>();
    worst = std::max(worst, drift[n]);
  }
  for (int a = 0; a < 3; ++a) table.add(prefix + std::to_string(a + 1), comp[a]);
  table.add(prefix + "_drift", drift);
  J0.assign(J.front().data(), J.front().data() + 3);
  return worst;
}

template <int S>
RunRecord solve_beanie_galerkin_on(const Scene& s, const Progress& progress) {
  using Sch = problems::BeanieGalerkin<S>;
  RunRecord r = start_record("solve", s);
  describe_solver(s, r);
  const auto make = [](const Scene& sc) {
    try {
      return problems::beanie_galerkin_bvp<S>(problems::BeanieModel{sc.beanie}, sc.T, sc.N, sc.beanie_start, sc.beanie_end);
    } catch (const std::invalid_argument& e) {
      throw SceneError(sc.file + ": boundary: " + e.what());
    }
  };
  const auto guess = [&](const GalerkinBVP<Sch>& bvp) {
    return problems::beanie_galerkin_guess<S>(bvp, s.beanie_start, s.beanie_end);
  };
  const auto res = solve_scene<Sch>(s, make, guess, progress, r);
  record_outcome(res, r);
  const GalerkinTrajectory<Sch>& tr = res.trajectory;
  if (tr.N() != s.N) return r;

  const problems::BeanieModel model{s.beanie};
  const auto g = tr.group();
  const int N = s.N;
  std::vector<double> t, psi, psi_dot, theta, x, y, u;
  std::vector<std::vector<double>> Omega(3);
  std::vector<Eigen::Vector3d> P;  // the free beanie's spatial momentum Ad*_{g^-1} (m Ω1, m Ω2, (I1 + I2) Ω3)
  for (int n = 0; n <= N; ++n) {
    t.push_back(tr.time(n));
    psi.push_back(tr.x(n)(0));
    psi_dot.push_back(tr.v(n)(0));
    theta.push_back(g[n].angle);
    x.push_back(g[n].t(0));
    y.push_back(g[n].t(1));
    const Eigen::Vector3d Om = tr.Omega(n);
    for (int i = 0; i < 3; ++i) Omega[i].push_back(Om(i));
    Jet<problems::BeanieModel, double> q;
    u.push_back(node_jet(model, tr, n, q) ? model.control(q) : nan());
    const Eigen::Vector3d M(s.beanie.m * Om(0), s.beanie.m * Om(1), (s.beanie.I1 + s.beanie.I2) * Om(2));
    P.push_back(SE2::Ad(SE2::inverse(g[n])).transpose() * M);
  }
  r.trajectory.add("t", t);
  r.trajectory.add("psi", psi);
  r.trajectory.add("theta", theta);
  r.trajectory.add("x", x);
  r.trajectory.add("y", y);
  for (int i = 0; i < 3; ++i) r.trajectory.add("Omega" + std::to_string(i + 1), Omega[i]);
  r.trajectory.add("psi_dot", psi_dot);
  r.trajectory.add("u", u);
  r.state_columns = {"psi", "theta", "x", "y"};
  r.final_state = {{"psi", psi.back()}, {"psi_dot", psi_dot.back()}, {"theta", theta.back()}, {"x", x.back()},
                   {"y", y.back()},     {"Omega1", Omega[0].back()}, {"Omega2", Omega[1].back()}, {"Omega3", Omega[2].back()}};

  // J_n (n = 0..N-1): the scheme's discrete momentum map.
  const auto J = galerkin_spatial_momentum(model, tr);
  std::vector<Eigen::Vector3d> Jv(J.begin(), J.end());
  r.momentum.add("t", t);
  r.has_momentum = true;
  r.momentum_drift = add_momentum(Jv, N, "J", r.momentum, r.momentum_initial);
  r.momentum_drift_relative = r.momentum_drift / std::max(1.0, Jv.front().lpNorm<Eigen::Infinity>());
  r.has_physical_momentum = true;
  r.physical_momentum_drift = add_momentum(P, N, "P", r.momentum, r.physical_momentum_initial);
  return r;
}

}  // namespace lpshoot::app
