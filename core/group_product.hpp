// The direct product A x B of two groups (e.g. SE(2) x SO(2) for a bundle whose symmetry
// group has two factors). Everything acts componentwise; tangent coordinates are A's then B's.
#pragma once

#include <Eigen/Core>

namespace lpshoot {

template <class A, class B>
struct Product {
  static constexpr int dim = A::dim + B::dim;
  template <class T>
  struct Element {
    typename A::template Element<T> first;
    typename B::template Element<T> second;
  };
  template <class T>
  using Tangent = Eigen::Matrix<T, dim, 1>;

  template <class T>
  static Element<T> identity() {
    return {A::template identity<T>(), B::template identity<T>()};
  }
  template <class T>
  static Element<T> compose(const Element<T>& a, const Element<T>& b) {
    return {A::compose(a.first, b.first), B::compose(a.second, b.second)};
  }
  template <class T>
  static Element<T> inverse(const Element<T>& a) {
    return {A::inverse(a.first), B::inverse(a.second)};
  }
  template <class T>
  static Element<T> exp(const Tangent<T>& xi) {
    return {A::template exp<T>(xi.template head<A::dim>()),
            B::template exp<T>(xi.template tail<B::dim>())};
  }
  template <class T>
  static Tangent<T> log(const Element<T>& g) {
    Tangent<T> xi;
    xi.template head<A::dim>() = A::log(g.first);
    xi.template tail<B::dim>() = B::log(g.second);
    return xi;
  }
  template <class T>
  static Eigen::Matrix<T, dim, dim> Ad(const Element<T>& g) {
    Eigen::Matrix<T, dim, dim> m = Eigen::Matrix<T, dim, dim>::Constant(T(0.0));
    m.template topLeftCorner<A::dim, A::dim>() = A::Ad(g.first);
    m.template bottomRightCorner<B::dim, B::dim>() = B::Ad(g.second);
    return m;
  }
  template <class T, class S>
  static Element<T> cast(const Element<S>& g) {
    return {A::template cast<T>(g.first), B::template cast<T>(g.second)};
  }
  // Block-diagonal matrix representation, for tests.
  static auto matrix(const Element<double>& g) {
    const auto ma = A::matrix(g.first);
    const auto mb = B::matrix(g.second);
    constexpr int ra = decltype(ma)::RowsAtCompileTime, rb = decltype(mb)::RowsAtCompileTime;
    Eigen::Matrix<double, ra + rb, ra + rb> m = Eigen::Matrix<double, ra + rb, ra + rb>::Zero();
    m.template topLeftCorner<ra, ra>() = ma;
    m.template bottomRightCorner<rb, rb>() = mb;
    return m;
  }
  static auto hat(const Tangent<double>& xi) {
    const auto ha = A::hat(xi.template head<A::dim>());
    const auto hb = B::hat(xi.template tail<B::dim>());
    constexpr int ra = decltype(ha)::RowsAtCompileTime, rb = decltype(hb)::RowsAtCompileTime;
    Eigen::Matrix<double, ra + rb, ra + rb> m = Eigen::Matrix<double, ra + rb, ra + rb>::Zero();
    m.template topLeftCorner<ra, ra>() = ha;
    m.template bottomRightCorner<rb, rb>() = hb;
    return m;
  }
};

}  // namespace lpshoot
