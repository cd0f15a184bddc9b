// `solve` for the beanie optimal-control scene (METHOD.md §6.2).
#include "paper_problems.hpp"
#include "run_common.hpp"

namespace lpshoot::app {

RunRecord solve_beanie(const Scene& s, const Progress& progress) {
  using problems::BeanieControl;
  RunRecord r = start_record("solve", s);
  describe_solver(s, r);
  r.constraints = s.scheme_options.at("constraints");
  const auto make = [](const Scene& sc) {
    BeanieControl bc;
    bc.par = beanie_parameters(sc.parameters);
    bc.variant = beanie_constraints(sc);
    try {
      return problems::beanie_bvp(bc, sc.T, sc.N, beanie_boundary(sc.start), beanie_boundary(sc.end), sc.closure);
    } catch (const std::invalid_argument& e) {
      throw SceneError(sc.file + ": boundary: " + e.what());
    }
  };
  const auto guess = [&](const BoundaryValueProblem<BeanieControl>& bvp) {
    return problems::beanie_guess(bvp, beanie_boundary(s.start), beanie_boundary(s.end));
  };
  const auto res = solve_scene<BeanieControl>(s, make, guess, progress, r);
  record_outcome(res, r);
  BeanieControl b;
  b.par = beanie_parameters(s.parameters);
  b.variant = beanie_constraints(s);
  const Trajectory<BeanieControl>& tr = res.trajectory;
  if (tr.N() != s.N) return r;

  beanie_state_columns(tr, res.g, r.trajectory);
  std::vector<double> u(s.N + 1, nan());
  std::vector<std::vector<double>> lam(3, std::vector<double>(s.N + 1, nan()));
  for (int n = 0; n + BeanieControl::order <= s.N; ++n) u[n] = b.control(tr.window_at(n), tr.h);
  for (size_t n = 0; n < tr.lam.size(); ++n)
    for (int i = 0; i < 3; ++i) lam[i][n] = tr.lam[n](i);
  r.trajectory.add("u", u);
  for (int i = 0; i < 3; ++i) r.trajectory.add("lambda" + std::to_string(i + 1), lam[i]);
  r.state_columns = {"psi", "theta", "x", "y"};

  const int N = s.N;
  r.final_state = {{"psi", tr.p[N](0)},
                   {"psi_dot", -end_velocity(tr.p[N](0), tr.p[N - 1](0), tr.p[N - 2](0), tr.h, s.closure)},
                   {"theta", res.g[N].angle},
                   {"x", res.g[N].t(0)},
                   {"y", res.g[N].t(1)},
                   {"Omega1", tr.g[N - 1].t(0) / tr.h},
                   {"Omega2", tr.g[N - 1].t(1) / tr.h},
                   {"Omega3", tr.g[N - 1].angle / tr.h}};
  record_momentum(b, tr, res.g[0], r);
  // The beanie's physical momentum: the free L_d (76) along the same motion.
  problems::BeanieFree free;
  free.par = b.par;
  Trajectory<problems::BeanieFree> motion;
  motion.h = tr.h;
  motion.p = tr.p;
  motion.g = tr.g;
  motion.lam.assign(tr.g.size(), Vec<double, 0>());
  r.has_physical_momentum = true;
  r.physical_momentum_drift = momentum_columns(free, motion, res.g[0], "P", r.momentum, &r.physical_momentum_initial, nullptr);
  return r;
}

}  // namespace lpshoot::app
