// The JSON account of a run or a sweep (report.hpp).
#include "report.hpp"

#include "problem.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace lpshoot::app {
namespace {

using json = nlohmann::ordered_json;

json finite_or_null(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

}  // namespace

json run_report(const Scene& scene, const RunRecord& r) {
  json j;
  j["lpshoot_version"] = "0.1.0";
  j["command"] = r.command;
  j["status"] = r.status;
  j["converged"] = r.converged;
  j["message"] = r.message;
  if (!r.detail.empty()) j["detail"] = r.detail;
  j["problem"] = r.problem;
  j["scene_file"] = scene.file;
  j["T"] = r.T;
  j["N"] = r.N;
  j["h"] = r.h;
  if (!r.method.empty()) {
    j["method"] = r.method;
    j["segments"] = r.segments;
    if (r.segments > 1) j["segment_starts"] = r.propagated_starts ? "forward sweep" : "guess";
    if (!r.coarse_grids.empty()) j["coarse_start"] = {{"grids", r.coarse_grids}, {"iterations", r.coarse_iterations}};
    j["backend"] = r.backend;
    j["scheme"] = r.scheme;
    if (!r.closure.empty()) j["closure"] = r.closure;
  } else {
    j["method"] = "discrete flow (Newton per step)";
    j["backend"] = "lpshoot step Newton";
  }
  if (!r.constraints.empty()) j["constraints"] = r.constraints;
  j["tolerance"] = r.tolerance;
  if (r.error_estimate) {
    const auto& e = *r.error_estimate;
    if (!e.failure.empty())
      j["error_estimate"] = {{"value", nullptr}, {"failure", e.failure}};
    else
      j["error_estimate"] = {{"value", e.value},
                             {"observed_order", e.order_observed ? json(e.observed_order) : json(nullptr)},
                             {"grids", {r.N, r.N / 2, r.N / 4}},
                             {"differences", {e.d_fine, e.d_coarse}},
                             {"columns", r.state_columns},
                             {"extrapolation_order", e.extrapolation_order},
                             {"wall_time_s", e.wall_time_s}};
  }
  if (!r.continuation_parameter.empty())
    j["continuation"] = {{"parameter", "parameters." + r.continuation_parameter},
                         {"path", r.continuation_path},
                         {"solves", r.continuation_solves}};
  j["cost"] = r.has_cost ? finite_or_null(r.cost) : json(nullptr);
  j["action"] = finite_or_null(r.action);
  j["iterations"] = r.iterations;
  j["residual_norm"] = finite_or_null(r.residual_norm);
  if (r.command == "solve") {
    j["raw_residual_norm"] = finite_or_null(r.raw_residual_norm);
    j["residual_history"] = json::array();
    for (double x : r.residual_history) j["residual_history"].push_back(finite_or_null(x));
    j["condition"] = finite_or_null(r.condition);
    j["rank"] = r.rank >= 0 ? json(r.rank) : json(nullptr);
    j["unknowns"] = r.unknowns;
    if (!r.dependent_conditions.empty()) j["dependent_conditions"] = r.dependent_conditions;
  } else {
    j["condition"] = finite_or_null(r.condition);  // the largest per-step Newton condition number
  }
  if (r.has_momentum) {
    j["momentum_drift"] = r.momentum_drift;
    j["momentum_drift_relative"] = r.momentum_drift_relative;
    j["momentum_initial"] = r.momentum_initial;
    if (r.has_physical_momentum) {
      j["physical_momentum_drift"] = r.physical_momentum_drift;
      j["physical_momentum_initial"] = r.physical_momentum_initial;
    }
  } else {
    j["momentum_drift"] = r.converged && r.problem == "electron" ? json(0.0) : json(nullptr);
    j["momentum_note"] = r.problem == "electron" ? "the symmetry group is trivial: no momentum map to conserve"
                                                 : "no trajectory";
  }
  if (!r.outputs_from.empty()) j["outputs_from"] = r.outputs_from;
  j["wall_time_s"] = r.wall_time_s;
  json fin = json::object();
  for (const auto& [k, v] : r.final_state) fin[k] = finite_or_null(v);
  j["final_state"] = fin;
  j["scene"] = json::parse(scene.effective_json);
  return j;
}

json sweep_report(const Scene& scene, const SweepRecord& sw) {
  json j;
  j["lpshoot_version"] = "0.1.0";
  j["command"] = "sweep";
  j["status"] = sw.all_converged ? "converged" : "not_converged";
  j["message"] = sw.message;
  j["problem"] = sw.problem;
  j["reference"] = sw.reference;
  j["error_columns"] = sw.error_columns;
  j["runs"] = json::array();
  for (const auto& r : sw.runs) {
    json x;
    x["N"] = r.N;
    x["h"] = r.h;
    if (!r.method.empty())
      x["scheme"] = r.scheme, x["method"] = r.method, x["backend"] = r.backend, x["segments"] = r.segments;
    x["status"] = r.status;
    x["converged"] = r.converged;
    if (!r.converged) x["message"] = r.message;
    x["error"] = finite_or_null(r.error);
    x["order"] = finite_or_null(r.order);
    x["cost"] = finite_or_null(r.cost);
    x["cost_error"] = finite_or_null(r.cost_error);
    x["wall_time_s"] = r.wall_time_s;
    x["iterations"] = r.iterations;
    x["momentum_drift"] = r.momentum_drift;
    j["runs"].push_back(x);
  }
  j["scene"] = json::parse(scene.effective_json);
  return j;
}

}  // namespace lpshoot::app
