// `solve` for the electron scene (METHOD.md §6.1) and its exact continuous reference.
#include "paper_problems.hpp"
#include "run_common.hpp"

#include <lpshoot/problems/electron_exact.hpp>

namespace lpshoot::app {

RunRecord solve_electron(const Scene& s, const Progress& progress) {
  using problems::Electron;
  RunRecord r = start_record("solve", s);
  describe_solver(s, r);
  const auto make = [](const Scene& sc) {
    return problems::electron_bvp(electron_of(sc.parameters), sc.T, sc.N, electron_boundary(sc.start),
                                  electron_boundary(sc.end), sc.closure);
  };
  const auto guess = [&](const BoundaryValueProblem<Electron>& bvp) {
    return problems::electron_guess(bvp, electron_boundary(s.start), electron_boundary(s.end));
  };
  const Electron electron = electron_of(s.parameters);
  const auto res = solve_scene<Electron>(s, make, guess, progress, r);
  record_outcome(res, r);
  const Trajectory<Electron>& tr = res.trajectory;
  if (tr.N() != s.N) return r;  // no trajectory to report (the flow failed or the problem was invalid)

  // Columns: t, x1..x3 at every node; u1..u3 on windows n = 0 .. N-2 (empty in the last two rows).
  std::vector<double> t;
  std::vector<std::vector<double>> x(3), u(3, std::vector<double>(s.N + 1, nan()));
  for (int n = 0; n <= s.N; ++n) {
    t.push_back(tr.time(n));
    for (int i = 0; i < 3; ++i) x[i].push_back(tr.p[n](i));
    if (n + Electron::order <= s.N) {
      const Eigen::Vector3d un = electron.control(tr.window_at(n), tr.h);
      for (int i = 0; i < 3; ++i) u[i][n] = un(i);
    }
  }
  r.trajectory.add("t", t);
  for (int i = 0; i < 3; ++i) r.trajectory.add("x" + std::to_string(i + 1), x[i]);
  for (int i = 0; i < 3; ++i) r.trajectory.add("u" + std::to_string(i + 1), u[i]);
  r.state_columns = {"x1", "x2", "x3"};
  const int N = s.N;
  for (int i = 0; i < 3; ++i) r.final_state.emplace_back("x" + std::to_string(i + 1), tr.p[N](i));
  for (int i = 0; i < 3; ++i)  // x'(T) by the closure's stencil, backwards from node N
    r.final_state.emplace_back("v" + std::to_string(i + 1),
                               -end_velocity(tr.p[N](i), tr.p[N - 1](i), tr.p[N - 2](i), tr.h, s.closure));
  return r;
}

ExactReference electron_exact_reference(const Scene& s, const std::vector<double>& times) {
  ExactReference ref;
  const problems::ElectronBoundary a = electron_boundary(s.start), b = electron_boundary(s.end);
  if (a.free_position || a.free_velocity || b.free_position || b.free_velocity) return ref;
  const auto exact = problems::electron_exact_optimum(electron_of(s.parameters), s.T, a.position, a.velocity, b.position, b.velocity);
  std::vector<std::vector<double>> x(3);
  for (double t : times) {
    const Eigen::Vector3d p = exact.position(t);
    for (int i = 0; i < 3; ++i) x[i].push_back(p(i));
  }
  ref.table.add("t", times);
  for (int i = 0; i < 3; ++i) ref.table.add("x" + std::to_string(i + 1), x[i]);
  ref.cost = exact.cost;
  // The oracle's linear system is solved to roundoff when the problem is well posed; a large
  // residual (or a non-finite solution) means it cannot support an error figure.
  ref.available = exact.y0.allFinite() && exact.residual < 1e-10;
  return ref;
}

}  // namespace lpshoot::app
