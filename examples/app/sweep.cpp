#include "sweep.hpp"

#include "problem.hpp"

#include <algorithm>
#include <cstdio>

namespace lpshoot::app {
namespace {

// Value of column `c` of a uniform-grid table at time t (a node when it is one, else linear
// interpolation between the neighbouring nodes).
double value_at(const Table& ref, int c, double t) {
  const std::vector<double>& ts = ref.columns[0];
  const int n = static_cast<int>(ts.size()) - 1;
  const double h = ts[n] / n;
  const double s = t / h;
  const int i = std::clamp(static_cast<int>(std::floor(s)), 0, n - 1);
  const double w = std::clamp(s - i, 0.0, 1.0);
  if (w < 1e-9) return ref.columns[c][i];
  if (w > 1 - 1e-9) return ref.columns[c][i + 1];
  return (1 - w) * ref.columns[c][i] + w * ref.columns[c][i + 1];
}

}  // namespace

double max_error(const Table& run, const Table& ref, const std::vector<std::string>& cols) {
  double e = 0;
  for (const auto& name : cols) {
    const int a = run.index(name), b = ref.index(name);
    if (a < 0 || b < 0) continue;
    for (size_t n = 0; n < run.rows(); ++n)
      e = std::max(e, std::abs(run.columns[a][n] - value_at(ref, b, run.columns[0][n])));
  }
  return e;
}

SweepRecord run_sweep(const Scene& scene, const std::string& command, const SweepOptions& opt, const Progress& progress) {
  SweepRecord rec;
  rec.problem = scene.problem_name;
  std::vector<int> grids = opt.N;
  std::sort(grids.begin(), grids.end());
  grids.erase(std::unique(grids.begin(), grids.end()), grids.end());
  if (!scene.is_optimal_control() && scene.initial.configurations)
    throw SceneError(scene.file + ": boundary.initial.configurations: q_0, q_1 belong to one grid; a sweep needs "
                                  "initial data as position and velocity");
  // The schemes (each a copy of the scene), solvers (simulations have none to choose), grids
  // coarse to fine, in that nesting.
  std::vector<Scene> schemes;
  for (const std::string& name : opt.schemes) {
    Scene sc = scene;
    const std::vector<std::string> names = scheme_names(scene.problem->descriptor());
    if (!scene.is_optimal_control() || std::find(names.begin(), names.end(), name) == names.end() || !set_scheme(sc, name)) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      throw SceneError("--scheme: '" + name + "' is not a scheme of " + scene.problem_name +
                       (!scene.is_optimal_control() ? " (a simulation has one scheme)" : " (" + list + ")"));
    }
    schemes.push_back(sc);
  }
  if (schemes.empty()) schemes.push_back(scene);
  for (const Scene& sc : schemes)
    if (grids.front() < sc.min_N())
      throw SceneError("--N: every N must be at least " +
                       (sc.galerkin() ? std::string("2 for ") + sc.scheme_name()
                                      : "2k + 1 = " + std::to_string(sc.min_N()) + " for " + scene.problem_name) +
                       " (got " + std::to_string(grids.front()) + ")");
  std::vector<std::pair<ShootingMethod, Backend>> solvers;
  for (ShootingMethod m : opt.methods.empty() ? std::vector{scene.shooting.method} : opt.methods)
    for (Backend b : opt.backends.empty() ? std::vector{scene.shooting.solver.backend} : opt.backends)
      if (scene.is_optimal_control() || solvers.empty()) solvers.emplace_back(m, b);
  // Every run planned (and checked against the machine's memory) before any is started.
  struct Planned {
    Scene scene;
    SweepRun run;
    std::string label;
  };
  std::vector<Planned> plan;
  for (const Scene& base : schemes)
    for (const auto& [m, b] : solvers)
      for (int N : grids) {
        Planned p{base, SweepRun(), "N = " + std::to_string(N)};
        Scene& s = p.scene;
        SweepRun& sr = p.run;
        s.N = N;
        s.error_estimate = false;  // the sweep measures errors itself
        sr.N = N;
        sr.h = s.h();
        if (scene.is_optimal_control()) {
          s.shooting.method = m;
          s.shooting.solver.backend = b;
          int segments = scene.shooting.segments;
          if (opt.steps_per_segment > 0) {  // ceil(N / steps), without overflowing int; kept as given
            segments = static_cast<int>((static_cast<long long>(N) + opt.steps_per_segment - 1) / opt.steps_per_segment);
            s.shooting.segment_doublings = 0;
          }
          else if (scene.auto_segments || scene.shooting.method == ShootingMethod::Single) {
            segments = s.default_segments(N);  // per grid (a single-shooting scene: multiple shooting's default)
            s.shooting.segment_doublings = auto_segment_doublings;  // as "auto" does (scene.cpp)
          }
          s.shooting.segments = std::clamp(segments, 1, s.max_segments(N));
          sr.scheme = s.scheme_name();
          sr.method = method_name(m);
          sr.backend = backend_name(b);
          sr.segments = m == ShootingMethod::Multiple ? s.shooting.segments : 1;
          p.label += ", " + sr.scheme + ", " + sr.method + " shooting" +
                     (m == ShootingMethod::Multiple ? " (" + std::to_string(sr.segments) + " segments)" : "") + ", " +
                     sr.backend;
        }
        if (const std::string why = resource_problem(s); !why.empty()) throw SceneError("--N: " + p.label + ": " + why);
        plan.push_back(std::move(p));
      }
  std::vector<RunRecord> full;
  for (Planned& p : plan) {
    if (progress) progress("[" + std::to_string(full.size() + 1) + "/" + std::to_string(plan.size()) + "] " + p.label);
    full.push_back(run_scene(command, p.scene, Progress()));
    const RunRecord& r = full.back();
    SweepRun& sr = p.run;
    sr.converged = r.converged;
    sr.segments = r.segments;  // "auto" may have doubled the planned count
    sr.status = r.status;
    sr.message = r.message;
    sr.iterations = r.iterations;
    sr.wall_time_s = r.wall_time_s;
    sr.momentum_drift = r.momentum_drift;
    if (r.has_cost) sr.cost = r.cost;
    rec.runs.push_back(sr);
    if (!r.converged && rec.all_converged) {
      rec.all_converged = false;
      rec.message = p.label + ": " + r.status + ": " + r.message;
    }
  }

  // Reference: the exact oracle, else the finest grid of the first solver.
  for (const auto& r : full)
    if (!r.state_columns.empty()) rec.error_columns = r.state_columns;
  Table ref;
  double ref_cost = nan();
  size_t ref_index = SIZE_MAX;
  const ExactReference exact = opt.use_exact ? exact_reference(scene, {}) : ExactReference{};
  if (exact.available) {
    rec.reference = "exact continuous optimum (matrix exponentials on short pieces)";
    ref_cost = exact.cost;
  } else {
    // The first solver's finest run of the highest-order scheme (paper: order 2 at best).
    size_t best = 0;
    for (size_t i = 1; i < schemes.size(); ++i)
      if ((schemes[i].galerkin() ? schemes[i].galerkin_order : 2) > (schemes[best].galerkin() ? schemes[best].galerkin_order : 2))
        best = i;
    ref_index = (best * solvers.size() + 1) * grids.size() - 1;
    const SweepRun& rr = rec.runs[ref_index];
    rec.reference = "finest grid (N = " + std::to_string(grids.back()) + ", " +
                    (rr.method.empty() ? std::string("discrete flow") : rr.scheme + ", " + rr.method + " shooting, " + rr.backend) +
                    ")";
    if (full[ref_index].converged) {
      ref = full[ref_index].trajectory;
      ref_cost = full[ref_index].has_cost ? full[ref_index].cost : nan();
    }
  }
  for (size_t i = 0; i < full.size(); ++i) {
    SweepRun& sr = rec.runs[i];
    if (!full[i].converged || i == ref_index) continue;
    if (exact.available) {
      const ExactReference at = exact_reference(scene, full[i].trajectory.columns[0]);
      sr.error = max_error(full[i].trajectory, at.table, rec.error_columns);
    } else if (ref.rows() > 0) {
      sr.error = max_error(full[i].trajectory, ref, rec.error_columns);
    }
    if (full[i].has_cost && std::isfinite(ref_cost)) sr.cost_error = std::abs(full[i].cost - ref_cost);
  }
  // Observed orders between consecutive grids of the same solver.
  for (size_t i = 1; i < rec.runs.size(); ++i) {
    SweepRun &a = rec.runs[i - 1], &b = rec.runs[i];
    // On the reference grid itself the error measures the solvers' disagreement, not the scheme.
    const bool on_reference_grid = !exact.available && b.N == grids.back();
    if (a.scheme == b.scheme && a.method == b.method && a.backend == b.backend && a.N < b.N && a.error > 0 && b.error > 0 &&
        !on_reference_grid)
      b.order = std::log(a.error / b.error) / std::log(double(b.N) / a.N);
  }
  return rec;
}

}  // namespace lpshoot::app
