// lpshoot: the command-line application (CLI11 stays in this file).
//   lpshoot solve SCENE.json [--out DIR] [--set key.path=value ...]
//   lpshoot simulate SCENE.json [...]
//   lpshoot sweep SCENE.json --N 50,100,200 [--scheme paper,galerkin4,galerkin6,galerkin8] [--method single,multiple]
//                [--backend kinsol,nlopt]
//   lpshoot check SCENE.json
//   lpshoot problems [--json]
//   lpshoot study STUDY.json [--out DIR] [--threads N] [--shard i/K]     (study_run.hpp)
//   lpshoot study merge DIR... --out DIR
// Every command takes --problem FILE.cpp (a problem of one's own, built once and cached; plugin.hpp).
// Exit codes: 0 converged; 1 the run did not converge (the report says why); 2 bad command line
// or scene; 3 the results could not be written; 4 an internal error or out of memory;
// 130 / 143 interrupted by SIGINT / SIGTERM (the report says so).
#include "describe.hpp"
#include "interrupt.hpp"
#include "output.hpp"
#include "plugin.hpp"
#include "study_cli.hpp"

#include <CLI/CLI.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <new>

namespace {

using namespace lpshoot;
using namespace lpshoot::app;

struct Common {
  std::string scene, out, plugin_cache;
  std::vector<std::string> sets, problem_files;
  bool no_plot = false, progress = false, quiet = false;
};

// Loads the --problem files (building those not cached yet); "" or the reason one failed.
std::string load_problem_files(const Common& c) {
  PluginOptions options;
  options.cache_dir = c.plugin_cache;
  if (!c.quiet) options.notify = [](const std::string& what) { std::fprintf(stderr, "lpshoot: %s\n", what.c_str()); };
  for (const auto& file : c.problem_files) {
    try {
      const LoadedPlugin p = load_problem_file(file, options);
      if (p.built && !c.quiet) std::fprintf(stderr, "lpshoot: built %s in %.1f s\n", file.c_str(), p.build_seconds);
    } catch (const PluginError& e) {
      return e.what();
    }
  }
  return "";
}

// Progress lines go to a terminal as they come; to a log (stderr not a terminal) at most one
// every 10 s, so a long run is visibly alive without flooding the log. Every call is also a
// checkpoint where SIGINT/SIGTERM stop the run.
Progress progress_printer(const Common& c) {
  const bool show = !c.quiet;
  const bool every_line = c.progress || isatty(STDERR_FILENO);
  auto last = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
  return [show, every_line, last](const std::string& line) {
    throw_if_interrupted();
    if (!show || line.empty()) return;  // an empty line is a checkpoint only
    const auto now = std::chrono::steady_clock::now();
    if (!every_line && now - *last < std::chrono::seconds(10)) return;
    *last = now;
    std::fprintf(stderr, "  %s\n", line.c_str());
  };
}

std::string fmt(const char* f, double x) {
  if (!std::isfinite(x)) return "not finite";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

std::string join_numbers(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ", ") + fmt("%.6g", x);
  return s;
}

void print_files(const Written& w) {
  for (const auto& warning : w.warnings) std::fprintf(stderr, "lpshoot: warning: %s\n", warning.c_str());
  std::printf("wrote:");
  for (const auto& f : w.files) std::printf(" %s", f.c_str());
  std::printf("\n");
}

void print_run(const RunRecord& r) {
  std::printf("%s %s: N = %d, T = %g, h = %g", r.command.c_str(), r.problem.c_str(), r.N, r.T, r.h);
  if (!r.method.empty()) {
    std::printf(", %s shooting%s, %s, %s scheme", r.method.c_str(),
                r.segments > 1 ? (" (" + std::to_string(r.segments) + " segments)").c_str() : "", r.backend.c_str(),
                r.scheme.c_str());
    if (!r.closure.empty()) std::printf(" (%s closure)", r.closure.c_str());
    if (!r.constraints.empty()) std::printf(", constraints %s", r.constraints.c_str());
  }
  std::printf("\nstatus: %s (%s)\n", r.status.c_str(), r.message.c_str());
  // NaN: not evaluated (the flow failed before the solver ran); "0" would read as a perfect solve.
  auto measured = [](double x, const char* none) { return std::isnan(x) ? std::string(none) : fmt("%.3g", x); };
  if (r.command == "solve")
    std::printf("residual: %s, Jacobian condition %s, rank %s of %d\n",
                std::isnan(r.residual_norm) ? "not evaluated"
                                            : (fmt("%.3g", r.residual_norm) + " x tolerance (raw " +
                                               measured(r.raw_residual_norm, "not evaluated") + ")")
                                                  .c_str(),
                measured(r.condition, "not computed").c_str(),
                r.rank >= 0 ? std::to_string(r.rank).c_str() : "not computed", r.unknowns);
  else
    std::printf("Newton: %d iterations over all steps, max step residual %s, max step condition %s\n", r.iterations,
                fmt("%.3g", r.residual_norm).c_str(), fmt("%.3g", r.condition).c_str());
  if (!r.converged) return;
  if (r.has_cost) std::printf("cost: %.15g\n", r.cost);
  else std::printf("action: %.15g\n", r.action);
  if (r.has_momentum)
    std::printf("momentum drift: max_n |J_n - J_0| = %.3e (relative %.3e), J_0 = (%s)\n", r.momentum_drift,
                r.momentum_drift_relative, join_numbers(r.momentum_initial).c_str());
  if (r.has_physical_momentum)
    std::printf("mechanical momentum drift: max_n |P_n - P_0| = %.3e, P_0 = (%s)\n", r.physical_momentum_drift,
                join_numbers(r.physical_momentum_initial).c_str());
  if (r.error_estimate) {
    const auto& e = *r.error_estimate;
    std::string cols;
    for (const auto& c : r.state_columns) cols += (cols.empty() ? "" : ", ") + c;
    if (!e.failure.empty())
      std::printf("error estimate: not available: %s\n", e.failure.c_str());
    else if (e.order_observed)
      std::printf("error estimate: %.3e, max over %s (observed order %.2f from N = %d, %d, %d; %.3f s more)\n", e.value,
                  cols.c_str(), e.observed_order, r.N, r.N / 2, r.N / 4, e.wall_time_s);
    else
      std::printf("error estimate: %.3e, max over %s (no convergence order observed from N = %d, %d, %d: the "
                  "difference to N/2 is given; refine N)\n",
                  e.value, cols.c_str(), r.N, r.N / 2, r.N / 4);
  }
  std::printf("final:");
  for (const auto& [k, v] : r.final_state) std::printf(" %s = %.10g", k.c_str(), v);
  std::printf("\nwall time: %.3f s\n", r.wall_time_s);
}

void print_sweep(const SweepRecord& sw) {
  std::printf("sweep %s: errors against the %s, max over nodes of |", sw.problem.c_str(), sw.reference.c_str());
  for (size_t i = 0; i < sw.error_columns.size(); ++i) std::printf("%s%s", i ? ", " : "", sw.error_columns[i].c_str());
  std::printf("|\n%7s %10s %-32s %-13s %10s %6s %12s %10s %9s %5s\n", "N", "h", "solver", "status", "error", "order",
              "cost", "cost err", "time [s]", "iter");
  for (const auto& r : sw.runs) {
    const std::string solver = r.method.empty() ? "flow"
                                                : r.scheme + "/" + r.method +
                                                      (r.segments > 1 ? "(" + std::to_string(r.segments) + ")" : "") + "/" + r.backend;
    auto opt = [](const char* f, double x) { return std::isfinite(x) ? fmt(f, x) : std::string("-"); };
    std::printf("%7d %10.4g %-32s %-13s %10s %6s %12s %10s %9.4f %5d\n", r.N, r.h, solver.c_str(), r.status.c_str(),
                opt("%.3e", r.error).c_str(), opt("%.2f", r.order).c_str(), opt("%.8g", r.cost).c_str(),
                opt("%.2e", r.cost_error).c_str(), r.wall_time_s, r.iterations);
  }
}

int fail_input(const std::string& what) {
  std::fprintf(stderr, "lpshoot: %s\n", what.c_str());
  return 2;
}

int run_command(int argc, char** argv) {
  CLI::App app{"lpshoot: optimal and free trajectories of mechanical systems with symmetry\n"
               "(discrete constrained higher-order Lagrange-Poincare equations, Bloch-Colombo-Jimenez)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "lpshoot 0.1.0");
  Common c;
  auto plugin_options = [&](CLI::App* sub) {
    sub->add_option("--problem", c.problem_files, "a problem of one's own: its C++ file (built once, then cached)")
        ->allow_extra_args(false);
    sub->add_option("--plugin-cache", c.plugin_cache,
                    "where built problems are cached (default: $LPSHOOT_PLUGIN_CACHE, else ~/.cache/lpshoot/plugins)");
  };
  auto scene_options = [&](CLI::App* sub, bool outputs) {
    sub->add_option("scene", c.scene, "the scene file (JSON; see the README's scene reference)")->required();
    plugin_options(sub);
    sub->add_option("--set", c.sets, "override a scene value, key.path=value (repeatable; value JSON or a word; null frees it)")
        ->allow_extra_args(false);
    if (!outputs) return;
    sub->add_option("--out", c.out, "output directory (default: the scene's output.dir, else lpshoot-out/SCENE)");
    sub->add_flag("--no-plot", c.no_plot, "do not draw PNG plots");
    sub->add_flag("--progress", c.progress, "show progress even when stderr is not a terminal");
    sub->add_flag("--quiet", c.quiet, "no progress lines");
  };
  CLI::App* solve = app.add_subcommand("solve", "solve the scene's boundary value problem (optimal control)");
  CLI::App* simulate = app.add_subcommand("simulate", "run the discrete flow from the scene's initial data");
  CLI::App* sweep = app.add_subcommand("sweep", "solve or simulate over several grids/solvers: error, order, time");
  CLI::App* check = app.add_subcommand("check", "validate the scene only");
  CLI::App* problems = app.add_subcommand("problems", "list the problems (built-in and --problem files) and their scene keys");
  CLI::App* study = app.add_subcommand("study", "solve a base scene over a grid of scene values, on every core\n"
                                                "  lpshoot study STUDY.json [--out DIR]   |   lpshoot study merge DIR... --out DIR");
  std::vector<std::string> study_args;
  std::string shard_text;
  int study_threads = 0;
  study->add_option("args", study_args, "the study file (README, \"Studies\"), or merge and the shard directories")->required();
  study->add_option("--out", c.out, "the study's directory (default: lpshoot-out/STUDY; required for merge)");
  study->add_option("--threads", study_threads, "points solved at once (default: one per core)")->check(CLI::PositiveNumber);
  double rank_timeout = 60;
  study->add_option("--rank-timeout", rank_timeout,
                    "under mpirun: seconds a rank may stay silent while solving before its points are marked lost "
                    "(default 60; run mpirun --enable-recovery so that the others survive it)")
      ->check(CLI::PositiveNumber);
  study->add_option("--shard", shard_text, "i/K: run only the points i, i+K, i+2K, ... (0 <= i < K; for job arrays)");
  study->add_flag("--no-plot", c.no_plot, "do not draw PNG plots");
  study->add_flag("--progress", c.progress, "show progress even when stderr is not a terminal");
  study->add_flag("--quiet", c.quiet, "no progress lines");
  plugin_options(study);
  bool problems_json_flag = false;
  plugin_options(problems);
  problems->add_flag("--json", problems_json_flag, "as JSON (one object per problem)");
  scene_options(solve, true);
  scene_options(simulate, true);
  scene_options(sweep, true);
  scene_options(check, false);
  std::vector<int> grids;
  std::vector<std::string> methods, backends, schemes;
  int steps_per_segment = 0;
  std::string reference = "auto";
  sweep->add_option("--N", grids, "grids, comma separated (e.g. 50,100,200,400)")->required()->delimiter(',');
  sweep->add_option("--scheme", schemes, "discretizations to compare (paper,galerkin4,galerkin6,galerkin8)")
      ->delimiter(',')
      ->check(CLI::IsMember({"paper", "galerkin4", "galerkin6", "galerkin8"}));
  sweep->add_option("--method", methods, "shooting methods to compare (single,multiple)")
      ->delimiter(',')
      ->check(CLI::IsMember({"single", "multiple"}));
  sweep->add_option("--backend", backends, "solver backends to compare (kinsol,nlopt)")
      ->delimiter(',')
      ->check(CLI::IsMember({"kinsol", "nlopt"}));
  sweep->add_option("--steps-per-segment", steps_per_segment, "multiple shooting: segments = ceil(N / this)")
      ->check(CLI::PositiveNumber);
  sweep->add_option("--reference", reference, "error reference: auto (exact where available) or finest")
      ->check(CLI::IsMember({"auto", "finest"}));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  for (CLI::App* sub : {solve, simulate, sweep})
    if (sub->parsed() && sub->count("--out") > 0 && c.out.empty())
      return fail_input("--out: the output directory is empty (give a directory, or leave --out out for the scene's)");

  if (const auto errors = registration_errors(); !errors.empty())
    throw std::logic_error("a built-in problem is ill-defined: " + errors.front());
  if (const std::string why = load_problem_files(c); !why.empty()) return fail_input(why);
  if (study->parsed()) {
    StudyCommand sc;
    sc.args = study_args;
    sc.out = c.out;
    sc.shard = shard_text;
    sc.threads = study_threads;
    sc.rank_timeout_s = rank_timeout;
    sc.plot = !c.no_plot;
    sc.progress = c.progress;
    sc.quiet = c.quiet;
    return run_study_command(sc);
  }
  if (problems->parsed()) {
    const std::string text = problems_json_flag ? problems_json(registered_problems()) : problems_text(registered_problems());
    std::fputs(text.c_str(), stdout);
    return 0;
  }

  Scene scene;
  try {
    scene = load_scene(c.scene, c.sets);
    if (const std::string why = check_boundary(scene); !why.empty())
      return fail_input(scene.file + ": boundary: " + why);
  } catch (const SceneError& e) {
    return fail_input(e.what());
  } catch (const std::bad_alloc&) {
    return fail_input(c.scene + ": the scene is too large to read");
  } catch (const std::exception& e) {
    return fail_input(c.scene + ": cannot read the scene: " + e.what());
  }
  if (check->parsed()) {
    std::printf("%s: valid %s scene: N = %d, T = %g, h = %g\n", scene.file.c_str(), scene.problem_name.c_str(), scene.N,
                scene.T, scene.h());
    return 0;
  }
  const std::string dir = c.out.empty() ? scene.out_dir : c.out;
  const bool plot = scene.plot && !c.no_plot;
  const Progress progress = progress_printer(c);
  const std::string command = sweep->parsed() ? "sweep" : solve->parsed() ? "solve" : "simulate";
  const auto started = std::chrono::steady_clock::now();
  std::unique_ptr<OutputDir> out;
  try {
    out = std::make_unique<OutputDir>(dir);  // before the work: an unwritable place fails now
  } catch (const OutputError& e) {
    std::fprintf(stderr, "lpshoot: cannot write the results: %s\n", e.what());
    return 3;
  }
  try {
    if (sweep->parsed()) {
      SweepOptions so;
      so.N = grids;
      so.schemes = schemes;
      for (const auto& m : methods) so.methods.push_back(m == "multiple" ? ShootingMethod::Multiple : ShootingMethod::Single);
      for (const auto& b : backends) so.backends.push_back(b == "nlopt" ? Backend::Nlopt : Backend::Kinsol);
      if (!scene.is_optimal_control() &&
          (!so.methods.empty() || !so.backends.empty() || !so.schemes.empty() || steps_per_segment > 0))
        return fail_input("--scheme/--method/--backend/--steps-per-segment: a " + scene.problem_name +
                          " simulation has no scheme or shooting solver to choose");
      so.steps_per_segment = steps_per_segment;
      so.use_exact = reference == "auto";
      const SweepRecord sw = run_sweep(scene, scene.is_optimal_control() ? "solve" : "simulate", so, progress);
      throw_if_interrupted();
      print_sweep(sw);
      print_files(write_sweep(scene, sw, *out, plot));
      if (!sw.all_converged) {
        std::fprintf(stderr, "lpshoot: not every run converged: %s\n", sw.message.c_str());
        return 1;
      }
      return 0;
    }
    const RunRecord r = run_scene(command, scene, progress);
    throw_if_interrupted();
    print_run(r);
    print_files(write_run(scene, r, *out, plot));
    if (!r.converged) {
      std::fprintf(stderr, "lpshoot: %s: %s\n", r.status.c_str(), r.message.c_str());
      return 1;
    }
    return 0;
  } catch (const SceneError& e) {
    return fail_input(e.what());
  } catch (const OutputError& e) {
    std::fprintf(stderr, "lpshoot: cannot write the results: %s\n", e.what());
    return 3;
  } catch (const Interrupted& e) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    std::fprintf(stderr, "lpshoot: %s after %.1f s; the report says so\n", e.what(), elapsed);
    try {
      OutputDir fresh(dir);  // the one that was being written may hold partial files
      print_files(write_interrupted(scene, command, fresh, e.what(), elapsed));
    } catch (const std::exception& w) {
      std::fprintf(stderr, "lpshoot: could not write the report: %s\n", w.what());
    }
    return 128 + e.signal;
  }
}

}  // namespace

// The one place every failure becomes a message and an exit code (2 input, 3 output, 4 internal).
int main(int argc, char** argv) {
  install_interrupt_handlers();
  try {
    return run_command(argc, argv);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "lpshoot: out of memory: the problem is too large for this machine (try a smaller N)\n");
    return 4;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lpshoot: internal error: %s\n", e.what());
    return 4;
  } catch (...) {
    std::fprintf(stderr, "lpshoot: internal error (unknown exception)\n");
    return 4;
  }
}
