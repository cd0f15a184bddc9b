// Functions of nested AD scalars by derivative towers (core/scalar_tower.hpp) against the same
// functions evaluated directly in the nested type: every value, first, second and third
// derivative, Taylor coefficients included.
#include <lpshoot/core/group_jets.hpp>
#include <lpshoot/core/groups.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace lpshoot;

namespace {

void flatten(double x, std::vector<double>& out) { out.push_back(x); }
template <class T, int N>
void flatten(const Dual<T, N>& x, std::vector<double>& out) {
  flatten(x.v, out);
  for (const T& d : x.d) flatten(d, out);
}
template <class T>
void flatten(const Taylor2<T>& x, std::vector<double>& out) {
  flatten(x.c0, out);
  flatten(x.c1, out);
  flatten(x.c2, out);
}
template <class T>
std::vector<double> flat(const T& x) {
  std::vector<double> out;
  flatten(x, out);
  return out;
}

// Every component of a and b agrees to tol relative to the largest component of b (or to
// tol · floor when that is larger).
template <class T>
void expect_same(const T& a, const T& b, double tol, const char* what, double floor = 1e-300) {
  const auto fa = flat(a), fb = flat(b);
  ASSERT_EQ(fa.size(), fb.size());
  double scale = floor;
  for (double v : fb) scale = std::max(scale, std::abs(v));
  for (size_t i = 0; i < fa.size(); ++i) EXPECT_NEAR(fa[i], fb[i], tol * scale) << what << " component " << i;
}

using D1 = Dual<double, 2>;
using D2 = Dual<D1, 2>;
using D3 = Dual<D2, 2>;

// w(x, y) = w0 + 0.3 x - 0.2 x y + 0.1 y^2 at (x, y) = (0.2, -0.1) minus its value plus w0, in
// the nested type: non-zero first, second and third derivatives of the argument.
D3 argument3(double w0) {
  const D3 x = D3::variable(D2::variable(D1::variable(0.2, 0), 1), 0);
  const D3 y = D3::variable(D2::variable(D1::variable(-0.1, 1), 0), 1);
  const D3 w = 0.3 * x - 0.2 * x * y + 0.1 * y * y * x;
  return w - value(w) + w0;
}

}  // namespace

TEST(ScalarTower, PolyGivesTaylorCoefficients) {
  const double x0 = 0.8;
  const Poly<5> s = Poly<5>::variable(x0);
  const Poly<5> q = sin(s) / (1.0 + s * s) + cos(s) * s;
  // Against a nested dual of order 3 evaluated directly: q'''(x0) = 3! [s^3] q.
  using T = Dual<Dual<Dual<double, 1>, 1>, 1>;
  const T x = T::variable(Dual<Dual<double, 1>, 1>::variable(Dual<double, 1>::variable(x0, 0), 0), 0);
  const T r = sin(x) / (1.0 + x * x) + cos(x) * x;
  EXPECT_NEAR(q.a[0], r.v.v.v, 1e-15);
  EXPECT_NEAR(q.a[1], r.d[0].v.v, 1e-14);
  EXPECT_NEAR(2 * q.a[2], r.d[0].d[0].v, 1e-14);
  EXPECT_NEAR(6 * q.a[3], r.d[0].d[0].d[0], 1e-13);
}

TEST(ScalarTower, SincAndCoscOfNestedTypesMatchDirectEvaluation) {
  // Every series regime of group_series.hpp and the closed form.
  for (double w0 : {0.0, 1e-9, 1e-5, 0.02, 0.3, 0.7, 2.5, -1.9}) {
    const D3 w = argument3(w0);
    expect_same(detail::sinc(w), detail::sinc_value(w), 1e-14, "sinc, triple dual");
    expect_same(detail::cosc(w), detail::cosc_value(w), 1e-14, "cosc, triple dual");
    // Taylor2 of a double dual: orders 4 (the Galerkin group jets).
    const D2 w2 = w.v;
    const Taylor2<D2> t(w2, 0.7 * w2 - value(w2) * 0.7 + 0.4, D2(-0.3) + w.d[1]);
    expect_same(detail::sinc(t), detail::sinc_value(t), 1e-14, "sinc, Taylor2");
    expect_same(detail::cosc(t), detail::cosc_value(t), 1e-14, "cosc, Taylor2");
  }
}

TEST(ScalarTower, LiftedRightJacobianInverseMatchesDirectEvaluation) {
  // ζ(x, y) with first and second derivatives (the Galerkin step's types).
  const D2 x = D2::variable(D1::variable(0.2, 0), 1), y = D2::variable(D1::variable(-0.1, 1), 0);
  for (double angle : {0.0, 1e-7, 0.3, 2.0}) {
    SE2::Tangent<D2> zeta;
    zeta(0) = 0.4 + x * y + 0.2 * y;
    zeta(1) = -0.7 + 0.3 * x * x - y;
    zeta(2) = angle + 0.5 * x - 0.25 * x * y + 0.1 * y * y;
    zeta(2) = zeta(2) - value(zeta(2)) + angle;
    const Eigen::Matrix<D2, 3, 3> lifted = right_jacobian_inverse<SE2, D2>(zeta);
    const Eigen::Matrix<D2, 3, 3> J = detail::right_jacobian_direct<SE2, D2>(zeta);
    for (int j = 0; j < 3; ++j) {
      Eigen::Matrix<D2, 3, 1> e = Eigen::Matrix<D2, 3, 1>::Constant(D2(0.0));
      e(j) = D2(1.0);
      const Eigen::Matrix<D2, 3, 1> col = solve_small<D2, 3>(J, e);
      for (int i = 0; i < 3; ++i) expect_same(lifted(i, j), col(i), 1e-13, "Jr^-1 entry");
    }
    // First order only.
    SE2::Tangent<D1> z1;
    for (int a = 0; a < 3; ++a) z1(a) = zeta(a).v;
    const Eigen::Matrix<D1, 3, 3> l1 = right_jacobian_inverse<SE2, D1>(z1);
    const Eigen::Matrix<D1, 3, 3> J1 = detail::right_jacobian_direct<SE2, D1>(z1);
    const Eigen::Matrix<D1, 3, 3> P = l1 * J1;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) expect_same(P(i, j), D1(i == j ? 1.0 : 0.0), 1e-13, "Jr^-1 Jr, first order", 1.0);
  }
}
