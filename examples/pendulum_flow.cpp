// The README's "your own problem" example: a pendulum written as a one-struct problem, stepped
// by the derived discrete flow. Prints the energy error at the end (a variational integrator
// keeps it bounded).
#include <lpshoot/core/lpshoot.hpp>

#include <cmath>
#include <cstdio>

struct Pendulum {  // shape p = angle, no symmetry, k = 1
  using Group = lpshoot::Trivial;
  static constexpr int shape_dim = 1, order = 1, num_constraints = 0;
  template <class T>
  T lagrangian(const lpshoot::Window<Pendulum, T>& a, double h) const {
    using std::cos;
    const T v = (a.p[1](0) - a.p[0](0)) / h;
    return h * (0.5 * v * v + cos(a.p[1](0)));
  }
};

int main() {
  const double h = 0.01;
  lpshoot::FlowState<Pendulum> init;  // p_0 .. p_{2k-1}
  init.p = {lpshoot::Vec<double, 1>(0.5), lpshoot::Vec<double, 1>(0.51)};
  const auto result = lpshoot::DiscreteFlow<Pendulum>(Pendulum{}, h).run(init, 10000);
  if (!result.report.ok()) {
    std::fprintf(stderr, "%s\n", result.report.message.c_str());  // names the step
    return 1;
  }
  auto energy = [&](int n) {
    const auto& p = result.trajectory.p;
    const double v = (p[n + 1](0) - p[n](0)) / h;
    return 0.5 * v * v - std::cos(0.5 * (p[n](0) + p[n + 1](0)));
  };
  double worst = 0;
  for (int n = 0; n < 10000; ++n) worst = std::max(worst, std::abs(energy(n) - energy(0)));
  std::printf("pendulum: 10000 steps of h = %g, max energy error %.3e\n", h, worst);
  return worst < 1e-3 ? 0 : 1;
}
