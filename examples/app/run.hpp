// One run of a scene (solve or simulate) as plain values: what report.json, trajectory.csv and
// the plots are written from, and what `sweep` compares across grids.
#pragma once

#include "scene.hpp"

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace lpshoot::app {

// Named columns of equal length; NaN marks "no value at this node" (written as an empty cell).
struct Table {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  void add(std::string name, std::vector<double> values) {
    names.push_back(std::move(name));
    columns.push_back(std::move(values));
  }
  size_t rows() const { return columns.empty() ? 0 : columns.front().size(); }
  int index(const std::string& name) const {
    for (size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return static_cast<int>(i);
    return -1;
  }
};

struct RunRecord {
  std::string command;  // "solve" or "simulate"
  bool converged = false;
  std::string status, message;  // message: one sentence (what failed, why, what to try)
  std::string detail;           // the solver's own account, in report.json only
  std::string problem;
  int N = 0;
  double T = 0, h = 0;
  std::string method, backend, closure, constraints;  // empty when not applicable
  std::string scheme;  // "paper" or "galerkin4" or "galerkin6" (Scene::scheme_name); empty for a simulation
  int segments = 1;
  bool propagated_starts = false;  // multiple shooting began from the forward sweep (SegmentStarts)
  std::vector<int> coarse_grids;   // the solve started from these grids' solutions (ShootingOptions::coarse_start_from)
  int coarse_iterations = 0;       // Newton iterations spent on them
  double tolerance = 0;
  bool has_cost = false;  // optimal control: ½ Σ h |u_n|^2
  double cost = 0;
  double action = 0;      // Σ L_d over the windows (the cost, for optimal control)
  int iterations = 0;     // shooting iterations, or Newton iterations over all steps (simulate)
  double residual_norm = 0, raw_residual_norm = 0, condition = 0;
  int rank = -1, unknowns = 0;  // rank -1: not computed
  std::vector<double> residual_history;
  std::vector<std::string> dependent_conditions;
  bool has_momentum = false;        // false when the symmetry group is trivial
  double momentum_drift = 0;        // max_n |J_n - J_0| (max-norm)
  double momentum_drift_relative = 0;
  std::vector<double> momentum_initial;
  // Optimal control: the mechanical system's own spatial momentum along the optimal motion (the
  // free L_d's J, conserved when the constraints are its exact equations; columns P*).
  bool has_physical_momentum = false;
  double physical_momentum_drift = 0;
  std::vector<double> physical_momentum_initial;
  double wall_time_s = 0;
  // Where the outputs' p'' comes from (core/galerkin_flow.hpp, node_jets): "legendre_transform"
  // or "node_differences" (the node velocities differentiated); empty: no outputs.
  std::string outputs_from;
  // solver.continuation: the parameter values solved, in order (the last is the scene's when
  // it was reached), and the number of solves including rejected steps.
  std::string continuation_parameter;
  std::vector<double> continuation_path;
  int continuation_solves = 0;
  // scheme.error_estimate: the run's error estimated from the same problem on N/2 and N/4
  // (Richardson with the observed order), max over state_columns at the common nodes.
  struct ErrorEstimate {
    double value = 0;                  // estimated max error of this run's state columns
    double observed_order = 0;         // log2(d_coarse / d_fine)
    double d_fine = 0, d_coarse = 0;   // max |x_N - x_{N/2}|, max |x_{N/2} - x_{N/4}|
    bool order_observed = false;       // false: value is d_fine itself (no asymptotic order seen)
    double wall_time_s = 0;            // of the two extra solves
    std::string failure;               // non-empty: a coarse solve failed, no estimate
    // Richardson extrapolation x_N + (x_N - x_{N/2}) / (2^p - 1) at the N/2 nodes, with p the
    // observed order rounded to an integer (0: not within 0.25 of one, no extrapolation).
    int extrapolation_order = 0;
    Table extrapolated;                // t and the state columns
  };
  std::optional<ErrorEstimate> error_estimate;
  std::vector<std::pair<std::string, double>> final_state;
  Table trajectory;                        // first column t
  Table momentum;                          // t, J1.., J_drift (, P1.., P_drift) when has_momentum
  std::vector<std::string> state_columns;  // the columns `sweep` measures errors on
};

// Progress lines for a terminal (the library never prints; the CLI decides where they go).
using Progress = std::function<void(const std::string&)>;

// Why the scene's boundary value problem is ill-posed by counting (METHOD.md §5), or "".
std::string check_boundary(const Scene& s);

// Dispatch by problem; throws SceneError when the command does not fit the problem.
RunRecord run_scene(const std::string& command, const Scene& s, const Progress& progress);

// The exact continuous answer at the given times, where the problem has one (the electron with
// all boundary data given): columns t, x1, x2, x3 and the exact cost. Empty otherwise.
struct ExactReference {
  bool available = false;
  Table table;
  double cost = 0;
};
ExactReference exact_reference(const Scene& s, const std::vector<double>& times);

// Shared helpers for the runners.
inline double nan() { return std::nan(""); }

}  // namespace lpshoot::app
