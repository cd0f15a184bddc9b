// Minimum-energy control of an electron in a magnetic field (paper §4.1.1, METHOD.md §6.1).
// Q = R^3 x S^1 with a trivial bundle; the S^1 part decouples and is dropped, so G is trivial,
// the shape is x in R^3, k = 2 and there is no constraint. With U_n the discrete control,
//   L_d = (h/2) |U_n|^2,  U_n = m (x_{n+2} - 2x_{n+1} + x_n)/h^2 + ∇φ(x_n) - (e/c) (x_{n+1} - x_n)/h × B,
// φ(x) = potential |x|^2 (the paper's case is potential = 1; the paper omits m).
#pragma once

#include <lpshoot/core/lpshoot.hpp>

namespace lpshoot::problems {

struct Electron {
  using Group = Trivial;
  static constexpr int shape_dim = 3;
  static constexpr int order = 2;
  static constexpr int num_constraints = 0;

  double mass = 1.0;
  double e_over_c = 1.0;
  Eigen::Vector3d B = Eigen::Vector3d(0, 0, 1);
  double potential = 1.0;

  template <class T>
  Vec<T, 3> control(const Window<Electron, T>& a, double h) const {
    const Vec<T, 3>& x0 = a.p[0];
    const Vec<T, 3> v = (a.p[1] - x0) / h;
    Vec<T, 3> vxB;
    vxB(0) = v(1) * B(2) - v(2) * B(1);
    vxB(1) = v(2) * B(0) - v(0) * B(2);
    vxB(2) = v(0) * B(1) - v(1) * B(0);
    return (mass / (h * h)) * (a.p[2] - 2.0 * a.p[1] + x0) + (2.0 * potential) * x0 - e_over_c * vxB;
  }

  template <class T>
  T lagrangian(const Window<Electron, T>& a, double h) const {
    return 0.5 * h * control(a, h).squaredNorm();
  }
};

// The continuous problem (METHOD.md §6.1, §9) for the Galerkin schemes: ℓ = ½ |u|² with
//   u = m x'' + ∇φ(x) - (e/c) x' × B,  φ(x) = potential |x|² + quartic x1⁴
// (quartic = 0 is the paper's electron; METHOD.md §9's nonlinear check uses potential = 1/2,
// quartic = 1/8).
struct ElectronModel {
  using Group = Trivial;
  static constexpr int shape_dim = 3;
  static constexpr int num_constraints = 0;

  double mass = 1.0;
  double e_over_c = 1.0;
  Eigen::Vector3d B = Eigen::Vector3d(0, 0, 1);
  double potential = 1.0;
  double quartic = 0.0;

  template <class T>
  Vec<T, 3> control(const Jet<ElectronModel, T>& q) const {
    const Vec<T, 3>& x = q.p;
    const Vec<T, 3>& v = q.dp;
    Vec<T, 3> vxB;
    vxB(0) = v(1) * B(2) - v(2) * B(1);
    vxB(1) = v(2) * B(0) - v(0) * B(2);
    vxB(2) = v(0) * B(1) - v(1) * B(0);
    Vec<T, 3> u = mass * q.ddp + (2.0 * potential) * x - e_over_c * vxB;
    if (quartic != 0.0) u(0) = u(0) + (4.0 * quartic) * x(0) * x(0) * x(0);
    return u;
  }
  template <class T>
  T lagrangian(const Jet<ElectronModel, T>& q) const {
    return 0.5 * control(q).squaredNorm();
  }
};

inline ElectronModel model_of(const Electron& e) { return {e.mass, e.e_over_c, e.B, e.potential, 0.0}; }

}  // namespace lpshoot::problems

extern template class lpshoot::DiscreteFlow<lpshoot::problems::Electron>;
