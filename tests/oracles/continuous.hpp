// Continuous-time optimal controls of the paper's examples (METHOD.md §6.1, §6.2): reference
// solutions ("oracles") against which the discrete optimal controls' convergence is measured.
#pragma once

#include <lpshoot/problems/beanie.hpp>
#include <lpshoot/problems/electron_exact.hpp>

#include <string>
#include <vector>

namespace lpshoot::oracles {

// Electron: the exact optimum lives with the problem (it also serves `lpshoot sweep`).
using problems::ElectronOptimum;
using problems::electron_exact_optimum;

// Elroy's beanie, METHOD.md §6.2, with natural terminal conditions (zero multipliers): the shape
// solves min ½ ∫_0^T u^2, u = μ ψ'' + V'(ψ), with ψ, ψ' given at both ends. Necessary conditions:
// ψ'' = (u − V'(ψ))/μ, u'' = −V''(ψ) u/μ; solved by Newton shooting on (u(0), u'(0)) with an
// adaptive dense-output Dormand–Prince integrator (tolerances 1e-13) and variational equations.
struct BeanieOptimum {
  bool converged = false;
  std::string message;
  int iterations = 0;      // Newton steps taken
  double u0 = 0, du0 = 0;  // u(0), u'(0)
  double cost = 0;         // ½ ∫ u^2 dt (integrated as an extra state component)
  // Values at the requested times (sorted, in [0, T]): psi, dpsi, u.
  std::vector<double> times, psi, dpsi, u;
};

// Throws std::invalid_argument unless T > 0 and times is sorted in [0, T]. Newton starts from the
// cubic Hermite interpolant of the boundary data (the exact answer when amplitude = 0).
BeanieOptimum beanie_continuous_optimum(const problems::BeanieParameters& par, double T, double psi0,
                                        double dpsi0, double psiT, double dpsiT,
                                        const std::vector<double>& times);

// The electron-type problem with a nonlinear potential (METHOD.md §9's check): ℓ = ½ |u|²,
// u = m x'' + ∇φ(x) - (e/c) x' × B, φ = potential |x|² + quartic x1⁴. Necessary conditions:
// m x'' = u - ∇φ(x) + (e/c) x' × B,  m u'' = (e/c) u' × B - ∇²φ(x) u; solved by Newton shooting on
// (u(0), u'(0)) (finite-difference Jacobian) with an adaptive dense-output Dormand–Prince
// integrator at tolerances 1e-13.
struct ElectronNonlinearOptimum {
  bool converged = false;
  int iterations = 0;
  double cost = 0;                        // ½ ∫ |u|² dt
  std::vector<Eigen::Vector3d> x, u;      // at the requested times
};

ElectronNonlinearOptimum electron_nonlinear_optimum(const problems::ElectronModel& model, double T,
                                                    const Eigen::Vector3d& x0, const Eigen::Vector3d& v0,
                                                    const Eigen::Vector3d& xT, const Eigen::Vector3d& vT,
                                                    const std::vector<double>& times);

}  // namespace lpshoot::oracles
