// Smooth helper functions for the closed forms of SO(2) and SE(2) exp/log.
//
// sinc(w) = sin(w)/w and cosc(w) = (1 - cos(w))/w, evaluated by their Taylor series for
// |w| < 0.5 (error below 1e-17 in the value and first two derivatives, exact at w = 0, which
// the engine hits at every Newton iterate) and by the closed form otherwise. cosc uses
// 2 sin^2(w/2)/w, which has no cancellation.
#pragma once

#include "scalar_tower.hpp"

#include <cmath>

namespace lpshoot::detail {

constexpr double kSeriesRadius = 0.5;

// Coefficients (-1)^j / (2j + 1 + shift)! of sum_j c_j w^(2j), j = 0..9.
constexpr double series_coefficient(int j, int shift) {
  double fact = 1.0;
  for (int i = 2; i <= 2 * j + 1 + shift; ++i) fact *= i;
  return ((j % 2 == 0) ? 1.0 : -1.0) / fact;
}

// sum_j (-1)^j w^(2j) / (2j + 1 + shift)!  for shift = 0 (sinc), 1 (cosc / w) and 2
// ((w - sin w) / w^3), by Horner.
template <class T>
T alternating_series(const T& w, int shift) {
  static constexpr double c0[10] = {
      series_coefficient(0, 0), series_coefficient(1, 0), series_coefficient(2, 0),
      series_coefficient(3, 0), series_coefficient(4, 0), series_coefficient(5, 0),
      series_coefficient(6, 0), series_coefficient(7, 0), series_coefficient(8, 0),
      series_coefficient(9, 0)};
  static constexpr double c1[10] = {
      series_coefficient(0, 1), series_coefficient(1, 1), series_coefficient(2, 1),
      series_coefficient(3, 1), series_coefficient(4, 1), series_coefficient(5, 1),
      series_coefficient(6, 1), series_coefficient(7, 1), series_coefficient(8, 1),
      series_coefficient(9, 1)};
  static constexpr double c2[10] = {
      series_coefficient(0, 2), series_coefficient(1, 2), series_coefficient(2, 2),
      series_coefficient(3, 2), series_coefficient(4, 2), series_coefficient(5, 2),
      series_coefficient(6, 2), series_coefficient(7, 2), series_coefficient(8, 2),
      series_coefficient(9, 2)};
  const double* c = shift == 0 ? c0 : shift == 1 ? c1 : c2;
  // Terms kept so that the first omitted one, and its first four derivatives, are below 1e-17
  // relative (nested duals carry second derivatives, and a Taylor2 of them two more): at w = 0
  // three terms are exact to the fourth derivative.
  const double a = std::abs(value(w));
  const int terms = a < 1e-8 ? 3 : a < 1e-3 ? 4 : a < 0.05 ? 6 : 10;
  const T w2 = w * w;
  T acc = T(c[terms - 1]);
  for (int j = terms - 2; j >= 0; --j) acc = acc * w2 + c[j];
  return acc;
}

template <class T>
T sinc_value(const T& w) {
  using std::sin;
  if (std::abs(value(w)) < kSeriesRadius) return alternating_series(w, 0);
  return sin(w) / w;
}

template <class T>
T cosc_value(const T& w) {
  using std::sin;
  if (std::abs(value(w)) < kSeriesRadius) return w * alternating_series(w, 1);
  const T s = sin(w * 0.5);
  return 2.0 * s * s / w;
}

// In AD types, by their derivatives at the value (scalar_tower.hpp), not Horner in the type.
template <class T>
T sinc(const T& w) {
  return apply_univariate(w, [](const auto& y) { return sinc_value(y); });
}

template <class T>
T cosc(const T& w) {
  return apply_univariate(w, [](const auto& y) { return cosc_value(y); });
}

// Angle wrapped to (-pi, pi], derivative 1.
template <class T>
T wrap_angle(const T& a) {
  const double two_pi = 2.0 * M_PI;
  double shift = std::round(value(a) / two_pi) * two_pi;
  T r = a - shift;
  if (value(r) <= -M_PI) r = r + two_pi;
  return r;
}

}  // namespace lpshoot::detail
