// The additive group R^n. Elements and algebra are both R^n; exp and log are the identity,
// Ad is the identity. Rn<0> is the trivial group (a trivial bundle with no symmetry).
#pragma once

#include <Eigen/Core>

namespace lpshoot {

template <int N>
struct Rn {
  static constexpr int dim = N;
  template <class T>
  using Element = Eigen::Matrix<T, N, 1>;
  template <class T>
  using Tangent = Eigen::Matrix<T, N, 1>;

  template <class T>
  static Element<T> identity() {
    return Element<T>::Constant(T(0.0));
  }
  template <class T>
  static Element<T> compose(const Element<T>& a, const Element<T>& b) {
    return a + b;
  }
  template <class T>
  static Element<T> inverse(const Element<T>& a) {
    return -a;
  }
  template <class T>
  static Element<T> exp(const Tangent<T>& xi) {
    return xi;
  }
  template <class T>
  static Tangent<T> log(const Element<T>& g) {
    return g;
  }
  template <class T>
  static Eigen::Matrix<T, N, N> Ad(const Element<T>&) {
    return Eigen::Matrix<T, N, N>::Identity();
  }
  template <class T, class S>
  static Element<T> cast(const Element<S>& g) {
    return g.template cast<T>();
  }
  // Homogeneous matrix representation [[I, g], [0, 1]] and algebra hat, for tests.
  static Eigen::Matrix<double, N + 1, N + 1> matrix(const Element<double>& g) {
    Eigen::Matrix<double, N + 1, N + 1> m = Eigen::Matrix<double, N + 1, N + 1>::Identity();
    m.template topRightCorner<N, 1>() = g;
    return m;
  }
  static Eigen::Matrix<double, N + 1, N + 1> hat(const Tangent<double>& xi) {
    Eigen::Matrix<double, N + 1, N + 1> m = Eigen::Matrix<double, N + 1, N + 1>::Zero();
    m.template topRightCorner<N, 1>() = xi;
    return m;
  }
};

using Trivial = Rn<0>;

}  // namespace lpshoot
