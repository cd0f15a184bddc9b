// Functions of nested AD scalars by derivative towers (core/scalar_tower.hpp) against the same
// functions evaluated directly in the nested type: every value, first, second and third
// derivative, Taylor coefficients included.
#include <lpshoot/core/group_jets.hpp>
#include <lpshoot/core/group_velocity_hessian.hpp>
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

namespace {
// Ω and Ω' of exp(ξ0 + ξ1 s + ξ2 s²/2) and Jr(ξ0)^{-1} ξ1 by the closed forms and by the
// generic routes, in second-order nested duals: the arguments depend on (x, y) with second
// derivatives.
template <class G>
void expect_closed_form_velocity_matches_generic(double angle) {
  static_assert(GroupVelocity<G>::closed_form);
  constexpr int d = G::dim;
  const D2 x = D2::variable(D1::variable(0.2, 0), 1), y = D2::variable(D1::variable(-0.1, 1), 0);
  typename G::template Tangent<Taylor2<D2>> xi;
  for (int a = 0; a < d; ++a) {
    const D2 c0 = (a == d - 1 ? angle : 0.4 - 0.3 * a) + 0.5 * x - 0.25 * x * y + (0.1 + 0.05 * a) * y * y;
    const D2 c1 = 0.7 - 0.6 * a + x * y - 0.3 * y + 0.2 * a * x * x;
    const D2 c2 = -0.4 + 0.35 * a + 0.3 * x * x + 0.5 * y;
    xi(a) = Taylor2<D2>(c0 - value(c0) + value(c0), c1, c2);
  }
  typename G::template Tangent<D2> x0, x1, x2, Om, dOm, Om_ref, dOm_ref;
  for (int a = 0; a < d; ++a) x0(a) = xi(a).c0, x1(a) = xi(a).c1, x2(a) = 2.0 * xi(a).c2;
  body_velocity_jet<G, D2>(x0, x1, x2, Om, dOm);
  body_velocity_jet_generic<G, D2>(x0, x1, x2, Om_ref, dOm_ref);
  for (int a = 0; a < d; ++a) {
    expect_same(Om(a), Om_ref(a), 1e-13, "Omega", 1.0);
    expect_same(dOm(a), dOm_ref(a), 1e-13, "dOmega", 1.0);
  }
  // Jr(ξ0)^{-1} ξ1 by the closed form against the inverted generic Jacobian.
  const typename G::template Tangent<D2> inv = right_jacobian_inverse_times<G, D2>(x0, x1);
  const typename G::template Tangent<D2> inv_ref = right_jacobian_inverse<G, D2>(x0) * x1;
  for (int a = 0; a < d; ++a) expect_same(inv(a), inv_ref(a), 1e-13, "Jr^-1 y", 1.0);
  // And in double.
  typename G::template Tangent<double> y0, y1, y2, O, dO, O_ref, dO_ref;
  for (int a = 0; a < d; ++a) y0(a) = value(x0(a)), y1(a) = value(x1(a)), y2(a) = value(x2(a));
  body_velocity_jet<G, double>(y0, y1, y2, O, dO);
  body_velocity_jet_generic<G, double>(y0, y1, y2, O_ref, dO_ref);
  EXPECT_LT((O - O_ref).norm(), 1e-14 * (1 + O_ref.norm()));
  EXPECT_LT((dO - dO_ref).norm(), 1e-14 * (1 + dO_ref.norm()));
}
}  // namespace

TEST(ScalarTower, ClosedFormBodyVelocityAndJacobianInverseMatchTheGroupsExpAndLog) {
  // Every series regime of group_series.hpp and group_velocity.hpp (|w| < 0.5, < 1) and the
  // closed forms; SE(2)'s translation part is the non-trivial one.
  for (double angle : {0.0, 1e-9, 1e-5, 0.02, 0.3, 0.7, 0.99, 1.3, 2.5, -1.9}) {
    SCOPED_TRACE(angle);
    expect_closed_form_velocity_matches_generic<SE2>(angle);
    expect_closed_form_velocity_matches_generic<SO2>(angle);
    expect_closed_form_velocity_matches_generic<Rn<2>>(angle);
    expect_closed_form_velocity_matches_generic<Product<SE2, SO2>>(angle);
  }
}

namespace {
// The seeded closed form (group_velocity_hessian.hpp) against the closed form run in Hess<3d>
// arithmetic, its variables placed at 1 + (k d + a) of Hess<3d + 2>: every value, gradient and
// Hessian entry, including the directions the body velocity does not depend on (zero).
template <class G>
void expect_seeded_velocity_matches_hess_arithmetic(double angle) {
  static_assert(SeededVelocity<G>::available);
  constexpr int d = G::dim, n = 3 * d, N = n + 2;
  using TX = Hess<n>;
  using T = Hess<N>;
  double x[3][d];
  for (int a = 0; a < d; ++a) {
    x[0][a] = a == d - 1 ? angle : 0.4 - 0.3 * a;
    x[1][a] = 0.7 - 0.6 * a;
    x[2][a] = -0.4 + 0.35 * a;
  }
  typename G::template Tangent<TX> x0, x1, x2, Om_ref, dOm_ref;
  for (int a = 0; a < d; ++a) {
    x0(a) = TX::variable(x[0][a], a);
    x1(a) = TX::variable(x[1][a], d + a);
    x2(a) = TX::variable(x[2][a], 2 * d + a);
  }
  GroupVelocity<G>::template jet<TX>(x0, x1, x2, Om_ref, dOm_ref);
  T Om[d], dOm[d];
  const auto idx = [](int k, int a) { return 1 + k * d + a; };
  SeededVelocity<G>::template jet<N>(x[0], x[1], x[2], idx, Om, dOm);
  auto check = [&](const T& got, const TX& ref, const char* what) {
    SCOPED_TRACE(what);
    const double tol = 1e-14;
    EXPECT_NEAR(got.v, ref.v, tol * (1 + std::abs(ref.v)));
    EXPECT_EQ(got.g[0], 0.0);
    EXPECT_EQ(got.g[N - 1], 0.0);
    for (int i = 0; i < N; ++i)
      for (int j = i; j < N; ++j) {
        const bool inside = i >= 1 && j >= 1 && i <= n && j <= n;
        const double want = inside ? ref.hessian(i - 1, j - 1) : 0.0;
        EXPECT_NEAR(got.hessian(i, j), want, tol * (1 + std::abs(want))) << "H(" << i << ", " << j << ")";
        if (i == j && inside) {
          EXPECT_NEAR(got.g[i], ref.g[i - 1], tol * (1 + std::abs(ref.g[i - 1])));
        }
      }
  };
  for (int a = 0; a < d; ++a) {
    check(Om[a], Om_ref(a), "Omega");
    check(dOm[a], dOm_ref(a), "dOmega");
  }
}
}  // namespace

TEST(ScalarTower, SeededBodyVelocityHessianMatchesTheClosedFormInHessArithmetic) {
  for (double angle : {0.0, 1e-9, 1e-5, 0.02, 0.3, 0.49, 0.51, 0.7, 0.99, 1.01, 1.3, 2.5, -1.9}) {
    SCOPED_TRACE(angle);
    expect_seeded_velocity_matches_hess_arithmetic<SE2>(angle);
    expect_seeded_velocity_matches_hess_arithmetic<SO2>(angle);
    expect_seeded_velocity_matches_hess_arithmetic<Rn<2>>(angle);
    expect_seeded_velocity_matches_hess_arithmetic<Product<SE2, SO2>>(angle);
  }
}
