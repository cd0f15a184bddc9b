// SO(2), stored as an angle (any real; compose adds angles). Algebra coordinate: the angular
// velocity w, hat(w) = [[0, -w], [w, 0]] (counter-clockwise, METHOD.md convention C).
// log wraps to (-pi, pi]; Ad is the identity (abelian).
#pragma once

#include "group_series.hpp"

#include <Eigen/Core>

namespace lpshoot {

struct SO2 {
  static constexpr int dim = 1;
  template <class T>
  struct Element {
    T angle;
  };
  template <class T>
  using Tangent = Eigen::Matrix<T, 1, 1>;

  template <class T>
  static Element<T> identity() {
    return {T(0.0)};
  }
  template <class T>
  static Element<T> compose(const Element<T>& a, const Element<T>& b) {
    return {a.angle + b.angle};
  }
  template <class T>
  static Element<T> inverse(const Element<T>& a) {
    return {-a.angle};
  }
  template <class T>
  static Element<T> exp(const Tangent<T>& xi) {
    return {xi(0)};
  }
  template <class T>
  static Tangent<T> log(const Element<T>& g) {
    return Tangent<T>(detail::wrap_angle(g.angle));
  }
  template <class T>
  static Eigen::Matrix<T, 1, 1> Ad(const Element<T>&) {
    return Eigen::Matrix<T, 1, 1>(T(1.0));
  }
  template <class T, class S>
  static Element<T> cast(const Element<S>& g) {
    return {T(g.angle)};
  }
  // Rotation matrix R(a) = [[cos a, -sin a], [sin a, cos a]].
  template <class T>
  static Eigen::Matrix<T, 2, 2> rotation(const T& a) {
    using std::cos;
    using std::sin;
    const T c = cos(a), s = sin(a);
    Eigen::Matrix<T, 2, 2> R;
    R << c, -s, s, c;
    return R;
  }
  static Eigen::Matrix2d matrix(const Element<double>& g) { return rotation(g.angle); }
  static Eigen::Matrix2d hat(const Tangent<double>& xi) {
    Eigen::Matrix2d m;
    m << 0, -xi(0), xi(0), 0;
    return m;
  }
};

}  // namespace lpshoot
