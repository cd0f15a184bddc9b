// Which runner a command and a scene call for.
#include "problem.hpp"
#include "run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace lpshoot::app {

std::string check_boundary(const Scene& s) { return s.problem->check_boundary(s); }

ExactReference exact_reference(const Scene& s, const std::vector<double>& times) {
  return s.problem->exact_reference(s, times);
}

namespace {

RunRecord run_one(const std::string& command, const Scene& s, const Progress& progress) {
  if (command == "simulate") {
    if (s.is_optimal_control())
      throw SceneError(s.file + ": problem: \"" + s.problem_name +
                       "\" is an optimal control problem (a boundary value problem): run `lpshoot solve` on it");
    return s.problem->simulate(s, progress);
  }
  if (!s.is_optimal_control())
    throw SceneError(s.file + ": problem: \"" + s.problem_name +
                     "\" is a simulation from initial data: run `lpshoot simulate` on it");
  return s.problem->solve(s, progress);
}

// max over the state columns of |a - b| at the nodes of b's grid (every `stride`-th node of a).
double max_difference(const RunRecord& a, const RunRecord& b, int stride) {
  double d = 0;
  for (const auto& name : a.state_columns) {
    const int ia = a.trajectory.index(name), ib = b.trajectory.index(name);
    for (size_t n = 0; n < b.trajectory.rows(); ++n)
      d = std::max(d, std::abs(a.trajectory.columns[ia][n * stride] - b.trajectory.columns[ib][n]));
  }
  return d;
}

// Richardson from three grids N, N/2, N/4: d_fine = |x_N - x_{N/2}|, d_coarse = |x_{N/2} - x_{N/4}|;
// with an error c h^p, d_coarse / d_fine = 2^p and the error of x_N is d_fine / (2^p - 1).
void estimate_error(const Scene& s, RunRecord& r, const Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<RunRecord> coarse;
  for (int f : {2, 4}) {
    Scene c = s;
    c.N = s.N / f;
    c.error_estimate = false;
    c.shooting.segments = c.auto_segments ? c.default_segments(c.N) : std::clamp(s.shooting.segments / f, 1, c.max_segments(c.N));
    if (progress) progress("error estimate: solving on N = " + std::to_string(c.N));
    coarse.push_back(run_one("solve", c, Progress()));
    if (!coarse.back().converged) {  // the run itself stands; only its estimate is missing
      RunRecord::ErrorEstimate e;
      e.failure = "the solve on N = " + std::to_string(c.N) + " did not converge (" + coarse.back().message + ")";
      r.error_estimate = e;
      return;
    }
  }
  RunRecord::ErrorEstimate e;
  e.d_fine = max_difference(r, coarse[0], 2);
  e.d_coarse = max_difference(coarse[0], coarse[1], 2);
  e.observed_order = e.d_fine > 0 && e.d_coarse > 0 ? std::log2(e.d_coarse / e.d_fine) : 0;
  e.order_observed = e.observed_order > 0.5;
  e.value = e.order_observed ? e.d_fine / (std::pow(2.0, e.observed_order) - 1) : e.d_fine;
  if (std::abs(e.observed_order - std::round(e.observed_order)) < 0.25 && std::round(e.observed_order) >= 1) {
    e.extrapolation_order = static_cast<int>(std::round(e.observed_order));
    const double factor = 1.0 / (std::pow(2.0, e.extrapolation_order) - 1);
    const RunRecord& half = coarse[0];
    e.extrapolated.add("t", half.trajectory.columns[0]);
    for (const auto& name : r.state_columns) {
      const auto& fine = r.trajectory.columns[r.trajectory.index(name)];
      const auto& c = half.trajectory.columns[half.trajectory.index(name)];
      std::vector<double> x(c.size());
      for (size_t n = 0; n < c.size(); ++n) x[n] = fine[2 * n] + factor * (fine[2 * n] - c[n]);
      e.extrapolated.add(name, x);
    }
  }
  e.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.error_estimate = e;
}

// Why a converged run's results are not all finite, or "". Tables mark "no value at this node"
// with NaN only in their first and last few rows (one-sided windows, the last interval's
// velocity); a NaN inside, or an infinity anywhere, is a failure. Names the first bad node.
std::string non_finite_result(const RunRecord& r) {
  auto scalar = [](const char* name, double x) { return std::isfinite(x) ? std::string() : std::string(name); };
  for (const std::string& why : {scalar("cost", r.has_cost ? r.cost : 0.0), scalar("action", r.action),
                                 scalar("momentum drift", r.momentum_drift),
                                 scalar("mechanical momentum drift", r.physical_momentum_drift)})
    if (!why.empty()) return "the " + why + " is not finite";
  for (const auto& [name, x] : r.final_state)
    if (!std::isfinite(x)) return "the final " + name + " is not finite";
  for (const Table* t : {&r.trajectory, &r.momentum}) {
    const size_t rows = t->rows(), edge = 4;
    for (size_t n = 0; n < rows; ++n)
      for (size_t c = 0; c < t->columns.size(); ++c) {
        const double x = t->columns[c][n];
        if (std::isinf(x) || (std::isnan(x) && n >= edge && n + edge < rows))
          return t->names[c] + " is not finite from node n = " + std::to_string(n) + " (t = " +
                 format_number(t->columns[0][n]) + ") on";
      }
  }
  return "";
}

}  // namespace

RunRecord run_scene(const std::string& command, const Scene& s, const Progress& progress) {
  RunRecord r = run_one(command, s, progress);
  if (r.converged) {
    if (const std::string why = non_finite_result(r); !why.empty()) {
      r.converged = false;
      r.status = "non_finite";
      r.message = why + ": the numbers overflowed (check the scene's magnitudes: parameters, boundary data, T)";
    }
  }
  if (s.error_estimate && r.converged) estimate_error(s, r, progress);
  return r;
}

}  // namespace lpshoot::app
