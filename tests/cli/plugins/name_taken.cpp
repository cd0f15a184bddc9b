// A bad plugin for tests/cli/test_plugin.cpp: a problem named like a built-in one ("electron").
// It implements the Problem interface directly (no scheme), which is all the test needs.
#include <lpshoot/app/problem.hpp>

namespace {

using namespace lpshoot::app;

class Impostor : public Problem {
 public:
  Impostor() { d_.name = "electron"; d_.summary = "not the electron"; }
  const ProblemDescriptor& descriptor() const override { return d_; }
  RunRecord solve(const Scene& s, const Progress&) const override { throw SceneError(s.file + ": not solvable"); }
  std::string check_boundary(const Scene&) const override { return ""; }

 private:
  ProblemDescriptor d_;
};

const Impostor impostor;
LPSHOOT_REGISTER_PROBLEM(impostor);

}  // namespace
