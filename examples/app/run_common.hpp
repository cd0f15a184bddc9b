// What the optimal-control runners share: the scene's solver settings into a RunRecord and the
// shooting outcome into it (included by run_electron.cpp and run_beanie.cpp only).
#pragma once

#include "run.hpp"

#include <lpshoot/shooting/continuation.hpp>

#include <chrono>
#include <cstdio>
#include <memory>

namespace lpshoot::app {

inline std::string format_value(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

inline RunRecord start_record(const std::string& command, const Scene& s) {
  RunRecord r;
  r.command = command;
  r.problem = s.problem_name;
  r.N = s.N;
  r.T = s.T;
  r.h = s.h();
  return r;
}

inline void describe_solver(const Scene& s, RunRecord& r) {
  r.method = method_name(s.shooting.method);
  r.backend = backend_name(s.shooting.solver.backend);
  r.scheme = s.scheme_name();
  if (!s.galerkin()) r.closure = closure_name(s.closure);
  r.segments = s.shooting.method == ShootingMethod::Multiple ? s.shooting.segments : 1;
  r.tolerance = s.shooting.solver.tolerance;
}

// Shooting options with a progress line per iteration, and within an evaluation that takes long
// (large N: seconds to minutes) a line every 5 s naming the segments propagated; every segment
// is an interrupt checkpoint (an empty line).
inline ShootingOptions options_with_progress(const Scene& s, const Progress& progress) {
  ShootingOptions opt = s.shooting;
  if (progress) {
    opt.solver.on_iteration = [progress](int it, double norm) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "iteration %d: residual %.3g x tolerance", it, norm);
      progress(buf);
    };
    auto last = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
    opt.on_segment = [progress, last](int done, int total) {
      const auto now = std::chrono::steady_clock::now();
      if (now - *last < std::chrono::seconds(5)) return progress(std::string());
      *last = now;
      progress("propagating: segment " + std::to_string(done) + " of " + std::to_string(total) + " done");
    };
  }
  return opt;
}

// Solves the scene's boundary value problem (make: Scene -> the scheme's BVP, guess: BVP -> the
// scheme's guess; P the paper's problem or a Galerkin scheme), through solver.continuation when
// the scene asks for it. The continuation record goes into r.
template <class P, class Make, class Guess>
ShootingResult<P> solve_scene(const Scene& s, const Make& make, const Guess& guess, const Progress& progress,
                              RunRecord& r) {
  using BVP = typename SchemeFor<P>::BVP;
  const ShootingOptions opt = options_with_progress(s, progress);
  if (!s.continuation) {
    const BVP bvp = make(s);
    return solve_bvp(bvp, guess(bvp), opt);
  }
  const Scene::Continuation& c = *s.continuation;
  const auto t0 = std::chrono::steady_clock::now();
  auto at = [&](double v) { return make(with_parameter(s, c.parameter, v)); };
  ContinuationOptions copt;
  copt.initial_step = c.initial_step;
  if (progress)
    copt.on_solve = [&](double v, bool ok, int iterations) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "continuation: parameters.%s = %.6g %s (%d iterations)", c.parameter.c_str(), v,
                    ok ? "solved" : "failed, step halved", iterations);
      progress(buf);
    };
  const BVP first = at(c.from);
  ContinuationResult<P> cont = continuation<P>(at, c.from, c.to, guess(first), opt, copt);
  r.continuation_parameter = c.parameter;
  r.continuation_path = cont.path;
  r.continuation_solves = cont.solves;
  ShootingResult<P> res = std::move(cont.result);
  if (!cont.reached && res.ok()) res.status = ShootingStatus::NotConverged;
  if (!cont.reached)
    res.message = "continuation in parameters." + c.parameter + " did not reach " + format_value(c.to) + ": " + res.message;
  res.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

template <class P>
void record_outcome(const ShootingResult<P>& res, RunRecord& r) {
  r.converged = res.ok();
  r.status = status_name(res.status);
  r.message = res.ok() ? "converged in " + std::to_string(res.iterations) + " iterations" : res.message;
  r.detail = res.detail;
  if (res.segments > 0) r.segments = res.segments;  // "auto" may have doubled the scene's count
  if (!res.failed_segment_counts.empty()) {  // named also on failure: fewer need not be tried again
    std::string counts;
    for (int c : res.failed_segment_counts) counts += (counts.empty() ? "" : ", ") + std::to_string(c);
    const std::string S = std::to_string(res.segments);
    r.message += res.ok() ? " with " + S + " segments, counting failed attempts with " + counts +
                                " (solver.segments \"auto\" doubles the segments when Newton does not converge)"
                          : " (with " + S + " segments; solver.segments \"auto\" tried " + counts + " first, see the detail)";
  }
  if (res.ok() && !res.coarse_grids.empty()) {
    std::string grids;
    for (int n : res.coarse_grids) grids += (grids.empty() ? "" : ", ") + std::to_string(n);
    r.message += ", from the solution on N = " + grids + " (" + std::to_string(res.coarse_iterations) +
                 " iterations there; ShootingOptions::coarse_start_from)";
  }
  if (res.ok() && res.propagated_starts)  // the scenes use SegmentStarts::Auto
    r.message += ", counting a failed attempt from the guess's segment starts before the forward sweep's";
  if (res.ok() && !r.continuation_path.empty())
    r.message += " (continuation in parameters." + r.continuation_parameter + ": " +
                 std::to_string(r.continuation_path.size()) + " values solved in " +
                 std::to_string(r.continuation_solves) + " solves)";
  r.iterations = res.iterations;
  r.propagated_starts = res.propagated_starts;
  r.coarse_grids = res.coarse_grids;
  r.coarse_iterations = res.coarse_iterations;
  r.residual_norm = res.residual_norm;
  r.raw_residual_norm = res.raw_residual_norm;
  r.condition = res.condition;
  r.rank = res.rank;
  r.unknowns = res.unknowns;
  r.residual_history = res.residual_history;
  r.dependent_conditions = res.dependent_conditions;
  r.wall_time_s = res.wall_time_s;
  r.has_cost = true;
  r.cost = r.action = res.cost;
}

// x'(t) at an end from the nodes, with the closure's own stencil.
inline double end_velocity(double p0, double p1, double p2, double h, Closure c) {
  return c == Closure::Paper ? (p1 - p0) / h : (-3 * p0 + 4 * p1 - p2) / (2 * h);
}

// Columns PREFIX1.., PREFIX_drift = |J_n - J_0| of the spatial momentum over the nodes 0..N
// (defined for n = k-1 .. N-k; empty cells elsewhere) into `table`; returns the max drift, and
// J_0 and the relative drift through the pointers.
template <class P>
double momentum_columns(const P& problem, const Trajectory<P>& tr, const GroupElement<P, double>& g0,
                        const std::string& prefix, Table& table, std::vector<double>* J0, double* relative) {
  const auto J = spatial_momentum(problem, tr, g0);
  constexpr int k = P::order, d = P::Group::dim;
  const int N = tr.N();
  if (table.names.empty()) {
    std::vector<double> t;
    for (int n = 0; n <= N; ++n) t.push_back(tr.time(n));
    table.add("t", t);
  }
  std::vector<std::vector<double>> comp(d, std::vector<double>(N + 1, nan()));
  std::vector<double> drift(N + 1, nan());
  double worst = 0;
  for (size_t i = 0; i < J.size(); ++i) {
    const int n = static_cast<int>(i) + k - 1;
    for (int a = 0; a < d; ++a) comp[a][n] = J[i](a);
    drift[n] = (J[i] - J.front()).template lpNorm<Eigen::Infinity>();
    worst = std::max(worst, drift[n]);
  }
  for (int a = 0; a < d; ++a) table.add(prefix + std::to_string(a + 1), comp[a]);
  table.add(prefix + "_drift", drift);
  if (J0) J0->assign(J.front().data(), J.front().data() + d);
  if (relative) *relative = worst / std::max(1.0, J.front().template lpNorm<Eigen::Infinity>());
  return worst;
}

template <class P>
void record_momentum(const P& problem, const Trajectory<P>& tr, const GroupElement<P, double>& g0, RunRecord& r) {
  r.has_momentum = true;
  r.momentum_drift = momentum_columns(problem, tr, g0, "J", r.momentum, &r.momentum_initial, &r.momentum_drift_relative);
}

// Columns shared by the control and free beanie: t, psi, theta, x, y (nodes 0..N) and
// Omega1..3 = g~_n / h (n = 0..N-1; the last row empty).
template <class P>
void beanie_state_columns(const Trajectory<P>& tr, const std::vector<SE2::Element<double>>& g, Table& out) {
  const int N = tr.N();
  std::vector<double> t, psi, theta, x, y;
  std::vector<std::vector<double>> Omega(3, std::vector<double>(N + 1, nan()));
  for (int n = 0; n <= N; ++n) {
    t.push_back(tr.time(n));
    psi.push_back(tr.p[n](0));
    theta.push_back(g[n].angle);
    x.push_back(g[n].t(0));
    y.push_back(g[n].t(1));
    if (n < N) {
      Omega[0][n] = tr.g[n].t(0) / tr.h;
      Omega[1][n] = tr.g[n].t(1) / tr.h;
      Omega[2][n] = tr.g[n].angle / tr.h;
    }
  }
  out.add("t", t);
  out.add("psi", psi);
  out.add("theta", theta);
  out.add("x", x);
  out.add("y", y);
  for (int i = 0; i < 3; ++i) out.add("Omega" + std::to_string(i + 1), Omega[i]);
}

}  // namespace lpshoot::app
