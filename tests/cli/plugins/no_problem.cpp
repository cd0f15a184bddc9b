// A bad plugin for tests/cli/test_plugin.cpp: it compiles, but registers no problem (a model
// without a descriptor or a registration).
#include <lpshoot/core/continuous.hpp>

namespace {

struct Lonely {
  using Group = lpshoot::Trivial;
  static constexpr int shape_dim = 1;
  static constexpr int num_constraints = 0;
  template <class T>
  T lagrangian(const lpshoot::Jet<Lonely, T>& q) const {
    return 0.5 * q.ddp(0) * q.ddp(0);
  }
};

}  // namespace

double lonely_lagrangian_at_rest() { return Lonely{}.lagrangian(lpshoot::Jet<Lonely, double>{}); }
