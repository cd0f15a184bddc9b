#include "oracles/continuous.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace lpshoot::oracles {

// ---------------------------------------------------------------- beanie, METHOD.md §6.2

namespace {
namespace odeint = boost::numeric::odeint;

// (ψ, ψ', u, u', J) followed by the two columns ∂(ψ, ψ', u, u')/∂u(0) and ∂(ψ, ψ', u, u')/∂u'(0).
using BeanieState = std::array<double, 13>;

struct BeanieSystem {
  double mu, a;  // V(ψ) = a (1 − cos ψ)
  void operator()(const BeanieState& y, BeanieState& dy, double /*t*/) const {
    const double s = std::sin(y[0]), c = std::cos(y[0]);
    dy[0] = y[1];
    dy[1] = (y[2] - a * s) / mu;  // μ ψ'' = u − V'(ψ)
    dy[2] = y[3];
    dy[3] = -a * c * y[2] / mu;  // μ u'' = −V''(ψ) u
    dy[4] = 0.5 * y[2] * y[2];
    for (int j = 5; j < 13; j += 4) {  // variational equations, linearised about (ψ, u)
      dy[j] = y[j + 1];
      dy[j + 1] = (y[j + 2] - a * c * y[j]) / mu;
      dy[j + 2] = y[j + 3];
      dy[j + 3] = a * (s * y[2] * y[j] - c * y[j + 2]) / mu;
    }
  }
};

// States at every grid time (grid[0] = 0, grid.back() = T, hit exactly by integrate_times).
std::vector<BeanieState> shoot(const BeanieSystem& sys, double psi0, double dpsi0, double u0, double du0,
                               const std::vector<double>& grid) {
  BeanieState y{};
  y[0] = psi0;
  y[1] = dpsi0;
  y[2] = u0;
  y[3] = du0;
  y[5 + 2] = 1;  // ∂u(0)/∂u(0)
  y[9 + 3] = 1;  // ∂u'(0)/∂u'(0)
  std::vector<BeanieState> out;
  out.reserve(grid.size());
  auto stepper = odeint::make_dense_output(1e-13, 1e-13, odeint::runge_kutta_dopri5<BeanieState>());
  odeint::integrate_times(stepper, sys, y, grid.begin(), grid.end(), grid.back() / 100,
                          [&out](const BeanieState& s, double) { out.push_back(s); });
  return out;
}
}  // namespace

BeanieOptimum beanie_continuous_optimum(const problems::BeanieParameters& par, double T, double psi0,
                                        double dpsi0, double psiT, double dpsiT,
                                        const std::vector<double>& times) {
  if (!(T > 0)) throw std::invalid_argument("beanie_continuous_optimum: T must be positive");
  if (!std::is_sorted(times.begin(), times.end()) || (!times.empty() && (times.front() < 0 || times.back() > T)))
    throw std::invalid_argument("beanie_continuous_optimum: times must be sorted in [0, T]");

  const BeanieSystem sys{par.mu(), par.amplitude};
  // Distinct grid times 0 < ... < T: the dense-output stepper cannot interpolate before its first
  // step, so t = 0 (and any repeated time) must appear only once.
  std::vector<double> grid{0.0};
  grid.insert(grid.end(), times.begin(), times.end());
  grid.push_back(T);
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());

  // Initial guess: the cubic Hermite ψ = ψ0 + ψ0' t + c2 t^2 + c3 t^3 and u = μ ψ'' + V'(ψ).
  const double gap = psiT - psi0 - dpsi0 * T, ddv = (dpsiT - dpsi0) * T;
  const double c2 = (3 * gap - ddv) / (T * T), c3 = (ddv - 2 * gap) / (T * T * T);
  Eigen::Vector2d z(sys.mu * 2 * c2 + sys.a * std::sin(psi0), sys.mu * 6 * c3 + sys.a * std::cos(psi0) * dpsi0);

  auto residual = [&](const std::vector<BeanieState>& traj) {
    return Eigen::Vector2d(traj.back()[0] - psiT, traj.back()[1] - dpsiT);
  };
  const double tol = 1e-11 * (1 + std::abs(psiT) + std::abs(dpsiT));
  const int max_iterations = 50;

  BeanieOptimum r;
  std::vector<BeanieState> traj = shoot(sys, psi0, dpsi0, z(0), z(1), grid);
  Eigen::Vector2d F = residual(traj);
  while (F.lpNorm<Eigen::Infinity>() > tol && r.iterations < max_iterations) {
    const BeanieState& yT = traj.back();
    Eigen::Matrix2d J;  // ∂(ψ(T), ψ'(T))/∂(u(0), u'(0)) from the variational columns
    J << yT[5], yT[9], yT[6], yT[10];
    const Eigen::Vector2d dz = -J.fullPivLu().solve(F);
    // Newton step, halved while it fails to reduce |F|.
    double step = 1;
    std::vector<BeanieState> trial;
    Eigen::Vector2d Ft;
    for (;;) {
      trial = shoot(sys, psi0, dpsi0, z(0) + step * dz(0), z(1) + step * dz(1), grid);
      Ft = residual(trial);
      if (Ft.norm() < F.norm() || step < 1e-3) break;
      step /= 2;
    }
    ++r.iterations;
    if (!(Ft.norm() < F.norm())) {
      r.message = "line search failed";
      break;
    }
    z += step * dz;
    traj = std::move(trial);
    F = Ft;
  }
  r.converged = F.lpNorm<Eigen::Infinity>() <= tol;
  if (r.converged)
    r.message = "converged";
  else if (!F.allFinite())
    r.message = "non-finite trajectory";
  else if (r.message.empty())
    r.message = "no convergence within the iteration limit";

  r.u0 = z(0);
  r.du0 = z(1);
  r.cost = traj.back()[4];
  r.times = times;
  for (double t : times) {
    const BeanieState& y = traj[std::lower_bound(grid.begin(), grid.end(), t) - grid.begin()];
    r.psi.push_back(y[0]);
    r.dpsi.push_back(y[1]);
    r.u.push_back(y[2]);
  }
  return r;
}

// ---------------------------------------------------------------- nonlinear electron, METHOD.md §9

namespace {
using ElectronState = std::array<double, 13>;  // x, x', u, u', ½ ∫ |u|²

struct ElectronSystem {
  const problems::ElectronModel& e;
  void operator()(const ElectronState& y, ElectronState& dy, double /*t*/) const {
    const Eigen::Vector3d x(y[0], y[1], y[2]), v(y[3], y[4], y[5]), u(y[6], y[7], y[8]), du(y[9], y[10], y[11]);
    Eigen::Vector3d grad = 2 * e.potential * x;
    grad(0) += 4 * e.quartic * x(0) * x(0) * x(0);
    Eigen::Matrix3d H = 2 * e.potential * Eigen::Matrix3d::Identity();
    H(0, 0) += 12 * e.quartic * x(0) * x(0);
    const Eigen::Vector3d ddx = (u - grad + e.e_over_c * v.cross(e.B)) / e.mass;
    const Eigen::Vector3d ddu = (e.e_over_c * du.cross(e.B) - H * u) / e.mass;
    for (int i = 0; i < 3; ++i) {
      dy[i] = v(i);
      dy[3 + i] = ddx(i);
      dy[6 + i] = du(i);
      dy[9 + i] = ddu(i);
    }
    dy[12] = 0.5 * u.squaredNorm();
  }
};

std::vector<ElectronState> shoot_electron(const problems::ElectronModel& e, const Eigen::Vector3d& x0,
                                          const Eigen::Vector3d& v0, const Eigen::Matrix<double, 6, 1>& z,
                                          const std::vector<double>& grid) {
  ElectronState y{};
  for (int i = 0; i < 3; ++i) {
    y[i] = x0(i);
    y[3 + i] = v0(i);
    y[6 + i] = z(i);
    y[9 + i] = z(3 + i);
  }
  std::vector<ElectronState> out;
  auto stepper = odeint::make_dense_output(1e-13, 1e-13, odeint::runge_kutta_dopri5<ElectronState>());
  odeint::integrate_times(stepper, ElectronSystem{e}, y, grid.begin(), grid.end(), grid.back() / 200,
                          [&out](const ElectronState& s, double) { out.push_back(s); });
  return out;
}
}  // namespace

ElectronNonlinearOptimum electron_nonlinear_optimum(const problems::ElectronModel& model, double T,
                                                    const Eigen::Vector3d& x0, const Eigen::Vector3d& v0,
                                                    const Eigen::Vector3d& xT, const Eigen::Vector3d& vT,
                                                    const std::vector<double>& times) {
  std::vector<double> grid{0.0};
  grid.insert(grid.end(), times.begin(), times.end());
  grid.push_back(T);
  std::sort(grid.begin(), grid.end());
  grid.erase(std::unique(grid.begin(), grid.end()), grid.end());
  auto residual = [&](const std::vector<ElectronState>& traj) {
    const ElectronState& y = traj.back();
    Eigen::Matrix<double, 6, 1> F;
    for (int i = 0; i < 3; ++i) {
      F(i) = y[i] - xT(i);
      F(3 + i) = y[3 + i] - vT(i);
    }
    return F;
  };
  ElectronNonlinearOptimum r;
  Eigen::Matrix<double, 6, 1> z = Eigen::Matrix<double, 6, 1>::Zero();
  auto traj = shoot_electron(model, x0, v0, z, grid);
  Eigen::Matrix<double, 6, 1> F = residual(traj);
  while (F.lpNorm<Eigen::Infinity>() > 1e-12 && r.iterations < 30) {
    Eigen::Matrix<double, 6, 6> J;
    for (int j = 0; j < 6; ++j) {  // central differences
      Eigen::Matrix<double, 6, 1> zp = z, zm = z;
      const double eps = 1e-6 * (1 + std::abs(z(j)));
      zp(j) += eps;
      zm(j) -= eps;
      J.col(j) = (residual(shoot_electron(model, x0, v0, zp, {0.0, T})) - residual(shoot_electron(model, x0, v0, zm, {0.0, T}))) / (2 * eps);
    }
    z -= J.fullPivLu().solve(F);
    traj = shoot_electron(model, x0, v0, z, grid);
    F = residual(traj);
    ++r.iterations;
  }
  r.converged = F.lpNorm<Eigen::Infinity>() <= 1e-12;
  r.cost = traj.back()[12];
  for (double t : times) {
    const ElectronState& y = traj[std::lower_bound(grid.begin(), grid.end(), t) - grid.begin()];
    r.x.emplace_back(y[0], y[1], y[2]);
    r.u.emplace_back(y[6], y[7], y[8]);
  }
  return r;
}

}  // namespace lpshoot::oracles
