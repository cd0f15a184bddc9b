// Which runner a command and a scene call for.
#include "run.hpp"

namespace lpshoot::app {

std::string check_boundary(const Scene& s) {
  try {
    if (s.problem == ProblemKind::Electron)
      return check_counting(problems::electron_bvp(s.electron, s.T, s.N, s.electron_start, s.electron_end, s.closure));
    if (s.problem == ProblemKind::Beanie) {
      problems::BeanieControl b;
      b.par = s.beanie;
      b.variant = s.constraints;
      return check_counting(problems::beanie_bvp(b, s.T, s.N, s.beanie_start, s.beanie_end, s.closure));
    }
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

RunRecord run_scene(const std::string& command, const Scene& s, const Progress& progress) {
  if (command == "simulate") {
    if (s.problem != ProblemKind::BeanieFree)
      throw SceneError(s.file + ": problem: \"" + s.problem_name +
                       "\" is an optimal control problem (a boundary value problem): run `lpshoot solve` on it");
    return simulate_beanie_free(s, progress);
  }
  switch (s.problem) {
    case ProblemKind::Electron: return solve_electron(s, progress);
    case ProblemKind::Beanie: return solve_beanie(s, progress);
    case ProblemKind::BeanieFree:
      throw SceneError(s.file + ": problem: \"beanie_free\" is a simulation from initial data: run `lpshoot simulate` on it");
  }
  return {};
}

}  // namespace lpshoot::app
