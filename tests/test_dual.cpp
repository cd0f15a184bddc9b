// The dual numbers against hand derivatives, first and (nested) second order.
#include <lpshoot/core/dual.hpp>

#include <gtest/gtest.h>

#include <cmath>

using lpshoot::Dual;

TEST(Dual, FirstDerivativesOfElementaryFunctions) {
  using D = Dual<double, 2>;
  const double x0 = 0.7, y0 = -1.3;
  const D x = D::variable(x0, 0), y = D::variable(y0, 1);
  const D f = sin(x) * exp(y) / (1.0 + x * x) + atan2(y, x) - sqrt(x) * log(2.0 + cos(y)) + pow(x, 3.5);
  const double den = 1 + x0 * x0;
  const double dfdx = std::cos(x0) * std::exp(y0) / den - std::sin(x0) * std::exp(y0) * 2 * x0 / (den * den) +
                      (-y0) / (x0 * x0 + y0 * y0) - 0.5 / std::sqrt(x0) * std::log(2 + std::cos(y0)) +
                      3.5 * std::pow(x0, 2.5);
  const double dfdy = std::sin(x0) * std::exp(y0) / den + x0 / (x0 * x0 + y0 * y0) +
                      std::sqrt(x0) * std::sin(y0) / (2 + std::cos(y0));
  EXPECT_NEAR(f.d[0], dfdx, 1e-14);
  EXPECT_NEAR(f.d[1], dfdy, 1e-14);
}

TEST(Dual, NestedDualsGiveTheHessian) {
  // f(x, y) = x^2 y + sin(x y): Hessian [[2y - y^2 sin, 2x + cos - x y sin], [.., -x^2 sin]].
  using In = Dual<double, 2>;
  using T = Dual<In, 2>;
  const double x0 = 0.4, y0 = 1.7;
  const T x = T::variable(In::variable(x0, 0), 0);
  const T y = T::variable(In::variable(y0, 1), 1);
  const T f = x * x * y + sin(x * y);
  const double s = std::sin(x0 * y0), c = std::cos(x0 * y0);
  EXPECT_NEAR(f.d[0].v, 2 * x0 * y0 + y0 * c, 1e-14);
  EXPECT_NEAR(f.d[0].d[0], 2 * y0 - y0 * y0 * s, 1e-14);
  EXPECT_NEAR(f.d[0].d[1], 2 * x0 + c - x0 * y0 * s, 1e-14);
  EXPECT_NEAR(f.d[1].d[0], 2 * x0 + c - x0 * y0 * s, 1e-14);
  EXPECT_NEAR(f.d[1].d[1], -x0 * x0 * s, 1e-14);
}

TEST(Dual, NonFiniteIsDetected) {
  using D = Dual<double, 1>;
  const D x = D::variable(-1.0, 0);
  EXPECT_FALSE(isfinite(sqrt(x)));
  EXPECT_TRUE(isfinite(x * x));
}
