// A problem the application can run (issue 10): its descriptor and what it does with a scene.
// Problems register themselves (LPSHOOT_REGISTER_PROBLEM in their own file); the scene reader
// finds them by name, so scene.cpp names none of them.
#pragma once

#include "run.hpp"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace lpshoot::app {

class Problem {
 public:
  virtual ~Problem() = default;
  virtual const ProblemDescriptor& descriptor() const = 0;
  // The scene's boundary value problem, solved on the scene's scheme.
  virtual RunRecord solve(const Scene& s, const Progress& progress) const = 0;
  // A free motion (descriptor().optimal_control false): the scene's initial data stepped N times.
  virtual RunRecord simulate(const Scene& s, const Progress&) const {
    throw SceneError(s.file + ": problem \"" + descriptor().name + "\" has no free-motion form to simulate");
  }
  // Why the scene's boundary conditions are ill-posed by counting (METHOD.md §5), or "".
  virtual std::string check_boundary(const Scene& s) const = 0;
  // The exact continuous answer at `times`, where the problem has one.
  virtual ExactReference exact_reference(const Scene&, const std::vector<double>&) const { return {}; }
  // Checks that involve several parameters, after each passed its own: the offending key (a path
  // under "parameters") and why, or nothing.
  virtual std::optional<std::pair<std::string, std::string>> check_parameters(const ParameterValues&) const {
    return std::nullopt;
  }
  // Why the problem's own definition is wrong (e.g. a descriptor naming more components than the
  // model has), or "". A problem with a definition error is not registered; the error is.
  virtual std::string definition_error() const { return ""; }
};

// Registration runs in static initialisers (a built-in problem's file, or a plugin being loaded),
// where nothing may throw: a problem that cannot be registered (a definition error, a name taken)
// is recorded in registration_errors() instead, for the application to report.
void register_problem(const Problem& problem);
const Problem* find_problem(const std::string& name);
std::vector<const Problem*> registered_problems();  // by name
std::vector<std::string> registration_errors();

struct ProblemRegistration {
  explicit ProblemRegistration(const Problem& problem) { register_problem(problem); }
};

}  // namespace lpshoot::app

#define LPSHOOT_CONCAT_INNER(a, b) a##b
#define LPSHOOT_CONCAT(a, b) LPSHOOT_CONCAT_INNER(a, b)
// Registers a Problem object with static storage duration (one line in the problem's file).
#define LPSHOOT_REGISTER_PROBLEM(object) \
  static const ::lpshoot::app::ProblemRegistration LPSHOOT_CONCAT(lpshoot_registration_, __LINE__)(object)
