// A problem of your own, solved as a boundary value problem: a pendulum (mass m, length l) hung
// from a cart (mass M) rolling freely on a rail. q = (x, ψ), ψ = 0 hanging down, and
//   L = ½(M+m) x'² + m l cos ψ x'ψ' + ½ m l² ψ'² + m g l cos ψ
// does not depend on the cart position x: G = R^1 moves the cart, the shape is ψ. The
// mechanical connection x' + m l cos ψ ψ'/(M+m) is the velocity of the centre of mass
// x_c = x + m l sin ψ/(M+m), so its exact integral A(ψ0, ψ1) = m l (sin ψ1 − sin ψ0)/(M+m) is
// the discrete connection and g~_n = Δx_n + A(ψ_n, ψ_{n+1}) = Δx_c. In these variables
// L = ½(M+m) x_c'² + ½ I(ψ) ψ'² + m g l cos ψ, I(ψ) = m l² (M + m sin²ψ)/(M+m); L_d is its
// midpoint rule.
#include <lpshoot/shooting/shooting.hpp>

#include <cmath>
#include <cstdio>

struct CartPendulum {
  using Group = lpshoot::Rn<1>;  // the cart position
  static constexpr int shape_dim = 1, order = 1, num_constraints = 0;
  double M = 1.0, m = 0.5, l = 1.0, g = 9.81;

  template <class T>
  T lagrangian(const lpshoot::Window<CartPendulum, T>& a, double h) const {
    using std::cos, std::sin;
    const T psi = 0.5 * (a.p[0](0) + a.p[1](0)), psi_dot = (a.p[1](0) - a.p[0](0)) / h;
    const T xc_dot = a.g[0](0) / h, s = sin(psi);
    const T I = m * l * l * (M + m * s * s) / (M + m);
    return h * (0.5 * (M + m) * xc_dot * xc_dot + 0.5 * I * psi_dot * psi_dot + m * g * l * cos(psi));
  }
  template <class T>
  lpshoot::Vec<T, 1> connection(const lpshoot::Vec<T, 1>& p0, const lpshoot::Vec<T, 1>& p1) const {
    using std::sin;
    return lpshoot::Vec<T, 1>(m * l * (sin(p1(0)) - sin(p0(0))) / (M + m));
  }
};

int main() {
  using namespace lpshoot;
  const CartPendulum cp;
  const double T = 1.0, psi0 = 0.3, psiT = -0.2, x0 = 0.0, xT = 0.5;
  const int N = 100;
  // k = 1: each end has one boundary node with r + d = 2 components (ψ, x). Prescribing both at
  // both ends (a Dirichlet problem on Q) gives each exactly one condition, and the 4 conditions
  // match the 4 unknowns (p_0, p_1, g~_0, g_0).
  BoundaryValueProblem<CartPendulum> bvp{cp, N, T, {}};
  bvp.fix_shape(End::Initial, 0, 0, psi0, "psi(0)");
  bvp.fix_group(End::Initial, 0, 0, Vec<double, 1>(x0), "x(0)");
  bvp.fix_shape(End::Terminal, 0, 0, psiT, "psi(T)");
  bvp.fix_group(End::Terminal, 0, 0, Vec<double, 1>(xT), "x(T)");

  // Guess: ψ and x linear in time.
  ShootingGuess<CartPendulum> guess;
  Trajectory<CartPendulum>& tr = guess.trajectory;
  tr.h = bvp.h();
  for (int n = 0; n <= N; ++n) tr.p.push_back(Vec<double, 1>(psi0 + (psiT - psi0) * n / N));
  for (int n = 0; n < N; ++n) tr.g.push_back(Vec<double, 1>((xT - x0) / N) + cp.connection(tr.p[n], tr.p[n + 1]));
  tr.lam.assign(N, Vec<double, 0>());  // no constraints: N - k + 1 empty multipliers
  guess.g0 = Vec<double, 1>(x0);

  const ShootingResult<CartPendulum> r = solve_bvp(bvp, guess);
  std::printf("status %s%s%s, %d iterations, residual %.2e\n", status_name(r.status), r.message.empty() ? "" : ": ",
              r.message.c_str(), r.iterations, r.raw_residual_norm);
  if (!r.ok()) return 1;
  std::printf("action %.10f, final psi %.12f, final x %.12f, momentum drift %.2e\n", r.cost,
              r.trajectory.p[N](0), r.g[N](0), r.momentum_drift);

  // Physics checks, on the reconstructed (x, ψ) and the original L. No horizontal force acts: the
  // centre of mass moves uniformly (exactly, in the discrete flow). The energy of L (velocities at
  // midpoints) is conserved to O(h²): a wrong I(ψ) or connection in the reduced L_d breaks both.
  const double h = bvp.h(), Mt = cp.M + cp.m;
  auto psi = [&](int n) { return r.trajectory.p[n](0); };
  auto xc = [&](int n) { return r.g[n](0) + cp.m * cp.l * std::sin(psi(n)) / Mt; };
  auto energy = [&](int n) {
    const double c = std::cos(0.5 * (psi(n) + psi(n + 1))), v = (r.g[n + 1](0) - r.g[n](0)) / h,
                 w = (psi(n + 1) - psi(n)) / h;
    return 0.5 * Mt * v * v + cp.m * cp.l * c * v * w + 0.5 * cp.m * cp.l * cp.l * w * w - cp.m * cp.g * cp.l * c;
  };
  double uniform_error = 0, energy_error = 0;
  for (int n = 0; n <= N; ++n)
    uniform_error = std::max(uniform_error, std::abs(xc(n) - (xc(0) + (xc(N) - xc(0)) * n / N)));
  for (int n = 0; n < N; ++n) energy_error = std::max(energy_error, std::abs(energy(n) - energy(0)));
  // The library's spatial momentum J is the horizontal momentum (M+m) x_c'.
  const double px = Mt * (xc(N) - xc(0)) / T, J = spatial_momentum(cp, r.trajectory, r.g[0]).front()(0);
  std::printf("horizontal momentum %.10f (J = %.10f), centre of mass off uniform motion by %.2e\n", px, J,
              uniform_error);
  std::printf("energy %.8f, max change %.2e\n", energy(0), energy_error);

  const bool hits_ends = std::abs(psi(0) - psi0) < 1e-8 && std::abs(r.g[0](0) - x0) < 1e-8 &&
                         std::abs(psi(N) - psiT) < 1e-8 && std::abs(r.g[N](0) - xT) < 1e-8;
  const bool ok = hits_ends && r.momentum_drift < 1e-10 && uniform_error < 1e-10 && std::abs(J - px) < 1e-10 &&
                  energy_error < 1e-4 * std::max(1.0, std::abs(energy(0)));
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
