// A scene: one problem instance read from a JSON file (README "Scene reference"), validated
// into typed values. Every error names the offending key and the file.
#pragma once

#include "descriptor.hpp"

#include <lpshoot/shooting/shooting.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace lpshoot::app {

// A scene that cannot be read or is invalid. what() is one line that names the file and key.
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Problem;  // problem.hpp

// scheme.discretization: the paper's nodal windows (with a closure), or Galerkin on node states
// of order 4, 6 or 8 (METHOD.md §9; 8 where the problem compiles it in, ModelProblem<Model, 8>).
enum class Discretization { Paper, Galerkin };

// A free motion's initial data (descriptor.configuration names the components): q_0, q_1
// directly, or a position and velocity (q_1 = q_0 + h q'(0), the paper's first-order closure).
struct InitialData {
  std::optional<std::array<Eigen::VectorXd, 2>> configurations;  // at nodes 0 and 1
  Eigen::VectorXd position, velocity;
};

struct Scene {
  std::string file;           // where it was read from (for messages)
  std::string effective_json; // the scene after --set overrides and defaults, pretty-printed
  const Problem* problem = nullptr;  // the registered problem (problem.hpp), never null once read
  std::string problem_name;
  int k = 2;  // the order of the paper's discretization (its windows have k + 1 nodes)
  double T = 1.0;
  int N = 100;

  Discretization discretization = Discretization::Paper;
  int galerkin_order = 4;  // scheme.order (Galerkin only): 4, 6 or 8
  Closure closure = Closure::SecondOrder;
  std::map<std::string, std::string> scheme_options;  // the problem's own paper-scheme choices (descriptor)
  ShootingOptions shooting;
  bool auto_segments = true;
  bool error_estimate = false;  // scheme.error_estimate: also solve on N/2 and N/4 (run.cpp)

  // solver.continuation: solve at parameters.<parameter> = from first, then step towards the
  // scene's own value, each solve starting from the last solution (shooting/continuation.hpp).
  struct Continuation {
    std::string parameter;  // key path under "parameters", e.g. "potential.amplitude" or "B.2"
    double from = 0, to = 0;
    double initial_step = 0.25;  // fraction of |to - from|
  };
  std::optional<Continuation> continuation;

  std::string out_dir;
  bool plot = true;

  ParameterValues parameters;      // under "parameters", validated against the descriptor
  BoundaryValues start, end;       // under "boundary.initial" and "boundary.final"
  InitialData initial;             // a free motion's initial data (under "boundary.initial")

  int order() const { return k; }
  double h() const { return T / N; }
  bool is_optimal_control() const;  // the problem is solved, not simulated
  bool galerkin() const { return discretization == Discretization::Galerkin; }
  // The smallest grid the scheme accepts: 2k + 1 nodes for the paper's windows, 2 intervals for Galerkin.
  int min_N() const { return galerkin() ? 2 : 2 * order() + 1; }
  // Multiple shooting's segment count: at most N - 2k + 1 (paper) or N (Galerkin).
  int max_segments(int n) const { return galerkin() ? n : n - 2 * order() + 1; }
  // solver.segments "auto": the library's choice, lpshoot::auto_segments (segments of at most
  // 100 steps), within this scheme's limit.
  int default_segments(int n) const { return std::clamp(lpshoot::auto_segments(n), 1, max_segments(n)); }
  // "paper", "galerkin4" or "galerkin6": the names `sweep --scheme` takes.
  std::string scheme_name() const { return galerkin() ? "galerkin" + std::to_string(galerkin_order) : "paper"; }
};

// Why the scene cannot run on this machine (its estimated memory exceeds 3/4 of the physical
// memory), or "". Checked when a scene is read and for every grid of a sweep.
std::string resource_problem(const Scene& s);

// The schemes a problem has, by the names scheme_name() gives: "paper" (with a discrete form),
// "galerkin4", "galerkin6", and "galerkin8" when compiled in; a free motion has "paper" only.
std::vector<std::string> scheme_names(const ProblemDescriptor& d);

// Sets the scheme from a name scheme_name() gives; false for an unknown name or one the scene's
// problem does not have (a Galerkin order not compiled into it).
bool set_scheme(Scene& s, const std::string& name);

// Reads, applies the --set overrides ("key.path=value", value parsed as JSON when it is JSON,
// else taken as a string; "null" removes the key), validates. Throws SceneError.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});
// The same from the scene's JSON text; `name` stands for the file in messages and in the default
// output directory (lpshoot-out/NAME).
Scene load_scene_text(const std::string& text, const std::string& name, const std::vector<std::string>& overrides = {});

// The scene with parameters.<parameter> set to value, validated again (throws SceneError).
Scene with_parameter(const Scene& s, const std::string& parameter, double value);

const char* closure_name(Closure c);
const char* method_name(ShootingMethod m);

}  // namespace lpshoot::app
