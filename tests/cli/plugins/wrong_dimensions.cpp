// A bad plugin for tests/cli/test_plugin.cpp: the descriptor names two shape components (and
// velocities) for a model with shape_dim = 1.
#include <lpshoot/app/model_problem.hpp>

namespace {

using namespace lpshoot;
using namespace lpshoot::app;

struct Line {
  using Group = Trivial;
  static constexpr int shape_dim = 1;
  static constexpr int num_constraints = 0;
  template <class T>
  T lagrangian(const Jet<Line, T>& q) const {
    return 0.5 * q.ddp(0) * q.ddp(0);
  }
};

ProblemDescriptor line_descriptor() {
  ProblemDescriptor d;
  d.name = "line";
  d.summary = "a descriptor that does not match its model";
  d.shape = {"x", "y"};
  d.velocity = {"vx", "vy"};
  return d;
}

const ModelProblem<Line> line(line_descriptor(), [](const ParameterValues&) { return Line{}; });
LPSHOOT_REGISTER_PROBLEM(line);

}  // namespace
