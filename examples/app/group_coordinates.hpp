// A group element in the coordinates a user thinks in, for boundary data and CSV columns:
// R^n its components, SO(2) the angle θ, SE(2) (x, y, θ). The order matches the algebra basis of
// each group (core/group_*.hpp), so coordinate i is the one a Galerkin boundary condition on
// group component i fixes (shooting/galerkin_boundary.hpp).
#pragma once

#include <lpshoot/core/problem.hpp>

namespace lpshoot::app {

template <class G>
struct GroupCoordinates {
  static_assert(sizeof(G) == 0, "no natural coordinates for this group yet (R^n, SO(2) and SE(2) have them)");
};

template <int N>
struct GroupCoordinates<Rn<N>> {
  static typename Rn<N>::template Element<double> element(const Vec<double, N>& c) { return c; }
  static Vec<double, N> coordinates(const typename Rn<N>::template Element<double>& g) { return g; }
};

template <>
struct GroupCoordinates<SO2> {
  static SO2::Element<double> element(const Vec<double, 1>& c) { return {c(0)}; }
  static Vec<double, 1> coordinates(const SO2::Element<double>& g) { return Vec<double, 1>(g.angle); }
};

template <>
struct GroupCoordinates<SE2> {
  static SE2::Element<double> element(const Vec<double, 3>& c) { return {c(2), Eigen::Vector2d(c(0), c(1))}; }
  static Vec<double, 3> coordinates(const SE2::Element<double>& g) { return Vec<double, 3>(g.t(0), g.t(1), g.angle); }
};

}  // namespace lpshoot::app
