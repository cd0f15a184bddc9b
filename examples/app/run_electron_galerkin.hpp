// `solve` for the electron scene on the Galerkin schemes of order 4 and 6 (METHOD.md §9): node
// positions and velocities are the unknowns; the control u = m x'' - (e/c) x' × B + ∇φ at each
// node comes from the scheme's discrete Legendre transform (node_jet).
#pragma once

#include "run_common.hpp"

namespace lpshoot::app {


template <int S>
RunRecord solve_electron_galerkin_on(const Scene& s, const Progress& progress) {
  using Sch = problems::ElectronGalerkin<S>;
  RunRecord r = start_record("solve", s);
  describe_solver(s, r);
  const auto make = [](const Scene& sc) {
    return problems::electron_galerkin_bvp<S>(problems::model_of(sc.electron), sc.T, sc.N, sc.electron_start, sc.electron_end);
  };
  const auto guess = [&](const GalerkinBVP<Sch>& bvp) {
    return problems::electron_galerkin_guess<S>(bvp, s.electron_start, s.electron_end);
  };
  const auto res = solve_scene<Sch>(s, make, guess, progress, r);
  record_outcome(res, r);
  const GalerkinTrajectory<Sch>& tr = res.trajectory;
  if (tr.N() != s.N) return r;

  // Columns at every node 0..N: t, x1..x3, v1..v3 (node data of the scheme), u1..u3.
  const problems::ElectronModel model = problems::model_of(s.electron);
  std::vector<double> t;
  std::vector<std::vector<double>> x(3), v(3), u(3);
  for (int n = 0; n <= s.N; ++n) {
    t.push_back(tr.time(n));
    const Eigen::Vector3d xn = tr.x(n), vn = tr.v(n);
    Jet<problems::ElectronModel, double> q;
    const bool have_u = node_jet(model, tr, n, q);
    const Eigen::Vector3d un = have_u ? Eigen::Vector3d(model.control(q)) : Eigen::Vector3d::Constant(nan());
    for (int i = 0; i < 3; ++i) x[i].push_back(xn(i)), v[i].push_back(vn(i)), u[i].push_back(un(i));
  }
  r.trajectory.add("t", t);
  for (int i = 0; i < 3; ++i) r.trajectory.add("x" + std::to_string(i + 1), x[i]);
  for (int i = 0; i < 3; ++i) r.trajectory.add("v" + std::to_string(i + 1), v[i]);
  for (int i = 0; i < 3; ++i) r.trajectory.add("u" + std::to_string(i + 1), u[i]);
  r.state_columns = {"x1", "x2", "x3"};
  for (int i = 0; i < 3; ++i) r.final_state.emplace_back("x" + std::to_string(i + 1), x[i].back());
  for (int i = 0; i < 3; ++i) r.final_state.emplace_back("v" + std::to_string(i + 1), v[i].back());
  return r;
}

}  // namespace lpshoot::app
