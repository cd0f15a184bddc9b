// A continuous model with every part of the jet nonlinear, for checks of derived derivatives:
// a shape-dependent connection on SE(2) × SO(2) (so the group is a product, the connection's
// derivatives do not vanish), a Lagrangian mixing p, p', p'', Ω and Ω', one constraint.
#pragma once

#include <lpshoot/core/lpshoot.hpp>

#include <cmath>

namespace lpshoot::test_support {

struct CurvedModel {
  using Group = Product<SE2, SO2>;
  static constexpr int shape_dim = 2;
  static constexpr int num_constraints = 1;
  template <class T>
  T lagrangian(const Jet<CurvedModel, T>& q) const {
    using std::cos, std::sin;
    return 0.5 * q.ddp.squaredNorm() + cos(q.p(0)) * q.Omega.squaredNorm() + q.dOmega(0) * q.dp(1) +
           0.3 * sin(q.Omega(2) * q.p(1)) + 0.2 * q.dOmega(3) * q.dOmega(1);
  }
  template <class T>
  Vec<T, 1> constraints(const Jet<CurvedModel, T>& q) const {
    using std::sin;
    return Vec<T, 1>(q.Omega(3) - q.dp(0) * sin(q.p(1)) + q.dOmega(2) * q.Omega(0));
  }
  template <class T>
  Eigen::Matrix<T, 4, 2> connection_form(const Vec<T, 2>& p) const {
    using std::cos, std::sin;
    Eigen::Matrix<T, 4, 2> A;
    A << sin(p(0)), p(1) * p(1), T(0.3), cos(p(1)) * p(0), p(0) * p(0) * p(0), T(0.5), T(0.1) * p(1), T(-0.2);
    return A;
  }
};

}  // namespace lpshoot::test_support
