// `lpshoot sweep`: one scene over several grids (and solvers), each run's error against an exact
// oracle where the problem has one, else against the finest grid; observed orders; cost per run.
#pragma once

#include "run.hpp"

namespace lpshoot::app {

struct SweepOptions {
  std::vector<int> N;                    // grids, any order
  std::vector<std::string> schemes;      // "paper", "galerkin4", ... (Scene::scheme_name); empty: the scene's
  std::vector<ShootingMethod> methods;   // empty: the scene's
  std::vector<Backend> backends;         // empty: the scene's
  int steps_per_segment = 0;             // > 0: multiple shooting segments = ceil(N / this)
  bool use_exact = true;                 // use the exact oracle when the problem has one
};

struct SweepRun {
  int N = 0, segments = 1, iterations = 0;
  double h = 0;
  std::string scheme, method, backend, status, message;
  bool converged = false;
  double error = nan();       // max over nodes and state columns of |run - reference|
  double order = nan();       // against the previous grid of the same solver
  double cost = nan(), cost_error = nan();
  double wall_time_s = 0, momentum_drift = 0;
};

struct SweepRecord {
  std::string problem, reference;  // "exact ..." or "finest grid ..."
  std::vector<std::string> error_columns;
  std::vector<SweepRun> runs;
  bool all_converged = true;
  std::string message;  // the first failure, when any
};

// Max over run's nodes and the columns `cols` of |run - ref|, ref (first column t, uniform grid)
// interpolated linearly where a node of run is not one of its nodes.
double max_error(const Table& run, const Table& ref, const std::vector<std::string>& cols);

// Throws SceneError for an N list or a scheme name that does not fit the scene. With several
// schemes and no exact oracle, the reference is the finest grid of the highest-order scheme.
SweepRecord run_sweep(const Scene& scene, const std::string& command, const SweepOptions& opt, const Progress& progress);

}  // namespace lpshoot::app
