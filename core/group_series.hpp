// Smooth helper functions for the closed forms of SO(2) and SE(2) exp/log.
//
// sinc(w) = sin(w)/w and cosc(w) = (1 - cos(w))/w, evaluated by their Taylor series for
// |w| < 0.5 (error below 1e-17 in the value and first two derivatives, exact at w = 0, which
// the engine hits at every Newton iterate) and by the closed form otherwise. cosc uses
// 2 sin^2(w/2)/w, which has no cancellation.
#pragma once

#include "scalar_tower.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace lpshoot::detail {

constexpr double kSeriesRadius = 0.5;

// Coefficients (-1)^j / (2j + 1 + shift)! of sum_j c_j w^(2j), j = 0..9.
constexpr double series_coefficient(int j, int shift) {
  double fact = 1.0;
  for (int i = 2; i <= 2 * j + 1 + shift; ++i) fact *= i;
  return ((j % 2 == 0) ? 1.0 : -1.0) / fact;
}

// How many derivatives a series is evaluated with: Poly<K> K (apply_univariate), other types
// their derivative_order, double 0.
template <class T>
struct series_order : derivative_order<T> {};
template <int K>
struct series_order<Poly<K>> : std::integral_constant<int, K> {};

constexpr int kSeriesTerms = 10;

// radius[n], n = 1 .. 10: the largest |w| at which the omitted terms j = n .. 9 of
// sum_j c_j w^(2j), and each of their first K derivatives, sum to at most 1e-18 (found by
// bisection, once). Below it, n terms give every derivative the caller carries to roundoff;
// more terms are wasted work. A term whose K-th derivative is a non-zero constant (2j <= K)
// is never omitted.
template <int K>
struct SeriesRadii {
  std::array<double, kSeriesTerms + 1> radius{};
  explicit SeriesRadii(const double* c) {
    // Powers by products, not std::pow: this runs once per process for each series and type,
    // ~2e4 powers each, and std::pow's ~1 ms in all was a tenth of a coarse solve's time in a
    // new process (beanie, Galerkin 8, N = 3).
    auto tail = [&](int n, double a) {
      std::array<double, 2 * kSeriesTerms> power{};
      power[0] = 1.0;
      for (int i = 1; i < 2 * kSeriesTerms; ++i) power[i] = power[i - 1] * a;
      double worst = 0;
      for (int k = 0; k <= K; ++k) {
        double sum = 0;
        for (int j = n; j < kSeriesTerms; ++j) {
          if (2 * j < k) continue;
          double falling = 1.0;  // (2j)! / (2j - k)!
          for (int i = 0; i < k; ++i) falling *= 2 * j - i;
          sum += std::abs(c[j]) * falling * power[2 * j - k];
        }
        worst = std::max(worst, sum);
      }
      return worst;
    };
    for (int n = 1; n < kSeriesTerms; ++n) {
      double lo = 0, hi = 2;
      if (tail(n, 0.0) > 1e-18) hi = 0;
      for (int it = 0; it < 60 && hi > 0; ++it) {
        const double mid = 0.5 * (lo + hi);
        (tail(n, mid) <= 1e-18 ? lo : hi) = mid;
      }
      radius[n] = lo;
    }
    radius[kSeriesTerms] = 1e300;  // the caller's radius: the full series
  }
  int terms(double a) const {
    int n = 1;
    while (!(a < radius[n])) ++n;
    return n;
  }
};

// sum_j c_j w^(2j) by Horner, with as many terms as value(w) and T's derivatives need
// (SeriesRadii); c holds kSeriesTerms coefficients, always the same array for a given Tag (the
// radii are computed once per T and Tag).
template <class T, int Tag>
T trimmed_series(const T& w, const double* c) {
  static const SeriesRadii<series_order<T>::value> radii(c);
  const int terms = radii.terms(std::abs(value(w)));
  const T w2 = w * w;
  T acc = T(c[terms - 1]);
  for (int j = terms - 2; j >= 0; --j) acc = acc * w2 + c[j];
  return acc;
}

// sum_j (-1)^j w^(2j) / (2j + 1 + shift)!  for shift = 0 (sinc), 1 (cosc / w) and 2
// ((w - sin w) / w^3). Used where |w| < 1: ten terms suffice there.
template <class T>
T alternating_series(const T& w, int shift) {
  static constexpr double c0[kSeriesTerms] = {
      series_coefficient(0, 0), series_coefficient(1, 0), series_coefficient(2, 0),
      series_coefficient(3, 0), series_coefficient(4, 0), series_coefficient(5, 0),
      series_coefficient(6, 0), series_coefficient(7, 0), series_coefficient(8, 0),
      series_coefficient(9, 0)};
  static constexpr double c1[kSeriesTerms] = {
      series_coefficient(0, 1), series_coefficient(1, 1), series_coefficient(2, 1),
      series_coefficient(3, 1), series_coefficient(4, 1), series_coefficient(5, 1),
      series_coefficient(6, 1), series_coefficient(7, 1), series_coefficient(8, 1),
      series_coefficient(9, 1)};
  static constexpr double c2[kSeriesTerms] = {
      series_coefficient(0, 2), series_coefficient(1, 2), series_coefficient(2, 2),
      series_coefficient(3, 2), series_coefficient(4, 2), series_coefficient(5, 2),
      series_coefficient(6, 2), series_coefficient(7, 2), series_coefficient(8, 2),
      series_coefficient(9, 2)};
  return shift == 0 ? trimmed_series<T, 0>(w, c0) : shift == 1 ? trimmed_series<T, 1>(w, c1) : trimmed_series<T, 2>(w, c2);
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
