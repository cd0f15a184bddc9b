// `simulate` for the free beanie scene: the k = 1 discrete flow from initial data.
#include "paper_problems.hpp"
#include "run_common.hpp"

#include <chrono>

namespace lpshoot::app {

RunRecord simulate_beanie_free(const Scene& s, const Progress& progress) {
  using problems::BeanieFree;
  const auto t0 = std::chrono::steady_clock::now();
  RunRecord r = start_record("simulate", s);
  r.tolerance = s.shooting.step.step_tolerance;
  BeanieFree problem;
  problem.par = beanie_parameters(s.parameters);
  const double h = s.h();
  Eigen::Vector4d q0, q1;  // (x, y, θ, ψ), the descriptor's configuration (problem_beanie_free.cpp)
  if (s.initial.configurations) {
    q0 = (*s.initial.configurations)[0];
    q1 = (*s.initial.configurations)[1];
  } else {  // q_1 = q_0 + h q'(0)
    q0 = s.initial.position;
    q1 = q0 + h * s.initial.velocity;
  }
  FlowState<BeanieFree> init;
  init.p = {Vec<double, 1>(q0(3)), Vec<double, 1>(q1(3))};
  init.g = {problems::beanie_increment(problem.par, q0, q1)};
  if (progress) progress("stepping " + std::to_string(s.N - 1) + " steps of h = " + std::to_string(h));
  const DiscreteFlow<BeanieFree> flow(problem, h, s.shooting.step);
  const FlowResult<BeanieFree> res = flow.run(init, s.N);
  r.converged = res.report.ok();
  r.status = res.report.ok() ? "converged" : "flow_failed";
  r.message = res.report.ok() ? "every step converged" : res.report.message;
  r.iterations = res.report.total_iterations;
  r.residual_norm = res.report.max_residual;
  r.condition = res.report.max_condition;
  const Trajectory<BeanieFree>& tr = res.trajectory;
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!r.converged) return r;

  const auto g0 = problems::beanie_group(q0);
  const auto g = reconstruct_group(problem, tr, g0);
  beanie_state_columns(tr, g, r.trajectory);
  r.state_columns = {"psi", "theta", "x", "y"};
  for (int j = 0; j + 1 <= tr.N(); ++j) r.action += problem.lagrangian(tr.window_at(j), h);
  const int N = s.N;
  r.final_state = {{"psi", tr.p[N](0)},       {"theta", g[N].angle},           {"x", g[N].t(0)},
                   {"y", g[N].t(1)},          {"Omega1", tr.g[N - 1].t(0) / h}, {"Omega2", tr.g[N - 1].t(1) / h},
                   {"Omega3", tr.g[N - 1].angle / h}};
  record_momentum(problem, tr, g0, r);
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace lpshoot::app
