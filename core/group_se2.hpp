// SE(2) = SO(2) x| R^2, element (R(angle), t) acting as x -> R x + t; stored as the angle and t.
// Algebra coordinates (v_x, v_y, w) with hat(v, w) = [[0, -w, v_x], [w, 0, v_y], [0, 0, 0]]
// (METHOD.md §6.2, convention C: [e1, e3] = -e2, [e2, e3] = e1).
//   compose: (a1, t1)(a2, t2) = (a1 + a2, t1 + R(a1) t2)
//   exp(v, w) = (w, V(w) v),  V(w) = [[sinc w, -cosc w], [cosc w, sinc w]]  (series near w = 0)
//   Ad_(a, t) = [[R(a), (t_y, -t_x)^T], [0, 0, 1]]
// log wraps the angle to (-pi, pi].
#pragma once

#include "group_so2.hpp"

#include <Eigen/Core>

namespace lpshoot {

struct SE2 {
  static constexpr int dim = 3;
  template <class T>
  struct Element {
    T angle;
    Eigen::Matrix<T, 2, 1> t;
  };
  template <class T>
  using Tangent = Eigen::Matrix<T, 3, 1>;

  template <class T>
  static Element<T> identity() {
    return {T(0.0), Eigen::Matrix<T, 2, 1>(T(0.0), T(0.0))};
  }
  template <class T>
  static Element<T> compose(const Element<T>& a, const Element<T>& b) {
    return {a.angle + b.angle, a.t + SO2::rotation(a.angle) * b.t};
  }
  template <class T>
  static Element<T> inverse(const Element<T>& a) {
    return {-a.angle, -(SO2::rotation(a.angle).transpose() * a.t)};
  }
  template <class T>
  static Eigen::Matrix<T, 2, 2> V(const T& w) {
    const T s = detail::sinc(w), c = detail::cosc(w);
    Eigen::Matrix<T, 2, 2> m;
    m << s, -c, c, s;
    return m;
  }
  template <class T>
  static Element<T> exp(const Tangent<T>& xi) {
    return {xi(2), V(xi(2)) * Eigen::Matrix<T, 2, 1>(xi(0), xi(1))};
  }
  template <class T>
  static Tangent<T> log(const Element<T>& g) {
    const T w = detail::wrap_angle(g.angle);
    const T s = detail::sinc(w), c = detail::cosc(w);
    const T det = s * s + c * c;
    Tangent<T> xi;
    xi(0) = (s * g.t(0) + c * g.t(1)) / det;
    xi(1) = (s * g.t(1) - c * g.t(0)) / det;
    xi(2) = w;
    return xi;
  }
  template <class T>
  static Eigen::Matrix<T, 3, 3> Ad(const Element<T>& g) {
    Eigen::Matrix<T, 3, 3> m;
    m.template topLeftCorner<2, 2>() = SO2::rotation(g.angle);
    m(0, 2) = g.t(1);
    m(1, 2) = -g.t(0);
    m(2, 0) = T(0.0);
    m(2, 1) = T(0.0);
    m(2, 2) = T(1.0);
    return m;
  }
  template <class T, class S>
  static Element<T> cast(const Element<S>& g) {
    return {T(g.angle), g.t.template cast<T>()};
  }
  static Eigen::Matrix3d matrix(const Element<double>& g) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    m.topLeftCorner<2, 2>() = SO2::rotation(g.angle);
    m.topRightCorner<2, 1>() = g.t;
    return m;
  }
  static Eigen::Matrix3d hat(const Tangent<double>& xi) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    m(0, 1) = -xi(2);
    m(1, 0) = xi(2);
    m(0, 2) = xi(0);
    m(1, 2) = xi(1);
    return m;
  }
};

}  // namespace lpshoot
