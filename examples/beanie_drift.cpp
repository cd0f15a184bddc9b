// Steps Elroy's beanie (free motion, k = 1, V = amplitude (1 - cos ψ)) and prints its spatial
// momentum and how far it drifts: the structure the discrete Lagrange–Poincaré flow keeps.
//   beanie_drift [N] [h] [amplitude]
#include <lpshoot/problems/beanie.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  using namespace lpshoot;
  using problems::BeanieFree;
  int N = 1000;
  double h = 0.01, amplitude = 1.0;
  try {
    if (argc > 1) N = std::stoi(argv[1]);
    if (argc > 2) h = std::stod(argv[2]);
    if (argc > 3) amplitude = std::stod(argv[3]);
  } catch (const std::exception&) {
    std::fprintf(stderr, "usage: beanie_drift [N] [h] [amplitude]  (N an integer, h and amplitude numbers)\n");
    return 2;
  }
  if (N < 2 || !(h > 0)) {
    std::fprintf(stderr, "beanie_drift: need N >= 2 and h > 0 (got N = %d, h = %g)\n", N, h);
    return 2;
  }
  BeanieFree problem;
  problem.par = {1.0, 1.0, 0.5, amplitude};
  // q(0) = (x, y, θ, ψ) = (0, 0, 0, 0.8), q'(0) = (1, 0.5, 0.3, 0): q_1 = q_0 + h q'(0).
  const Eigen::Vector4d q0(0, 0, 0, 0.8), v0(1.0, 0.5, 0.3, 0.0);
  const Eigen::Vector4d q1 = q0 + h * v0;
  FlowState<BeanieFree> init;
  init.p = {Vec<double, 1>(q0(3)), Vec<double, 1>(q1(3))};
  init.g = {problems::beanie_increment(problem.par, q0, q1)};

  const DiscreteFlow<BeanieFree> flow(problem, h);
  const FlowResult<BeanieFree> res = flow.run(init, N);
  if (!res.report.ok()) {
    std::fprintf(stderr, "beanie_drift: the flow failed: %s\n", res.report.message.c_str());
    return 1;
  }
  const auto g0 = problems::beanie_group(q0);
  const auto J = spatial_momentum(problem, res.trajectory, g0);
  double drift = 0;
  for (const auto& Jn : J) drift = std::max(drift, (Jn - J.front()).lpNorm<Eigen::Infinity>());
  const auto g = reconstruct_group(problem, res.trajectory, g0);
  std::printf("Elroy's beanie, free motion: N = %d steps of h = %g (T = %g), V = %g (1 - cos psi)\n", N, h,
              N * h, amplitude);
  std::printf("final (x, y, theta, psi) = (%.12g, %.12g, %.12g, %.12g)\n", g.back().t(0), g.back().t(1),
              g.back().angle, res.trajectory.p.back()(0));
  std::printf("spatial momentum J_0 = (%.15g, %.15g, %.15g)\n", J.front()(0), J.front()(1), J.front()(2));
  std::printf("momentum drift max_n |J_n - J_0| = %.3e (relative %.3e)\n", drift,
              drift / J.front().lpNorm<Eigen::Infinity>());
  std::printf("Newton: %d iterations in all, at most %d per step; max residual %.2e; max condition %.2e\n",
              res.report.total_iterations, res.report.max_iterations, res.report.max_residual,
              res.report.max_condition);
  return 0;
}
