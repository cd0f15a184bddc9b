// A bad plugin for tests/cli/test_plugin.cpp: a syntax error on line 9 (a missing semicolon).
#include <lpshoot/app/model_problem.hpp>

namespace {

struct Broken {
  using Group = lpshoot::Trivial;
  static constexpr int shape_dim = 1;
  static constexpr int num_constraints = 0
};

}  // namespace
