// Elroy's beanie moving freely (paper §4.2, METHOD.md §6.2): the k = 1 discrete flow from initial
// data (`lpshoot simulate`), with the beanie's parameters.
#include "paper_problems.hpp"
#include "problem.hpp"

namespace lpshoot::app {
namespace {

ProblemDescriptor beanie_free_descriptor() {
  ProblemDescriptor d;
  d.name = "beanie_free";
  d.summary = "Elroy's beanie moving freely from initial data (the paper's k = 1 flow; simulate)";
  d.parameters = beanie_descriptor().parameters;
  d.optimal_control = false;
  d.paper_order = 1;
  d.configuration = {"x", "y", "theta", "psi"};
  d.shape = {"psi"};
  d.group = {"theta", "x", "y"};
  d.omega = {"Omega1", "Omega2", "Omega3"};
  d.plots = {{"plane path", "x", {"y"}, true},
             {"shape and orientation", "t", {"psi", "theta"}, false},
             {"body velocity", "t", {"Omega1", "Omega2", "Omega3"}, false}};
  return d;
}

class BeanieFree : public Problem {
 public:
  const ProblemDescriptor& descriptor() const override { return descriptor_; }
  RunRecord simulate(const Scene& s, const Progress& progress) const override { return simulate_beanie_free(s, progress); }
  RunRecord solve(const Scene& s, const Progress&) const override {
    throw SceneError(s.file + ": problem: \"beanie_free\" is a simulation from initial data: run `lpshoot simulate` on it");
  }
  std::string check_boundary(const Scene&) const override { return ""; }

 private:
  ProblemDescriptor descriptor_ = beanie_free_descriptor();
};

const BeanieFree beanie_free;
LPSHOOT_REGISTER_PROBLEM(beanie_free);

}  // namespace
}  // namespace lpshoot::app
