// Group axioms and closed forms on random and near-identity elements: exp against the matrix
// exponential of hat, log as exp's inverse, compose/inverse as matrix products, Ad as conjugation,
// and automatic differentiation through exp and log.
#include <lpshoot/core/groups.hpp>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>
#include <gtest/gtest.h>

#include <random>

using namespace lpshoot;

template <class G>
class GroupTest : public ::testing::Test {
 protected:
  std::mt19937 rng{12345};
  using Tan = typename G::template Tangent<double>;
  Tan random_tangent(double scale) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Tan xi;
    for (int i = 0; i < G::dim; ++i) xi(i) = scale * u(rng);
    return xi;
  }
};

using Groups = ::testing::Types<Rn<3>, SO2, SE2, Product<SE2, SO2>>;
TYPED_TEST_SUITE(GroupTest, Groups);

TYPED_TEST(GroupTest, ExpMatchesMatrixExponential) {
  using G = TypeParam;
  for (double scale : {1e-9, 1e-3, 0.3, 2.5}) {
    for (int trial = 0; trial < 20; ++trial) {
      const auto xi = this->random_tangent(scale);
      const auto expected = G::hat(xi).exp().eval();
      EXPECT_LT((G::matrix(G::template exp<double>(xi)) - expected).norm(), 1e-13 * (1 + expected.norm()));
    }
  }
}

TYPED_TEST(GroupTest, LogInvertsExp) {
  using G = TypeParam;
  for (double scale : {1e-10, 1e-4, 0.4, 3.0}) {  // angles stay in (-pi, pi)
    for (int trial = 0; trial < 20; ++trial) {
      const auto xi = this->random_tangent(scale);
      const auto back = G::log(G::template exp<double>(xi));
      EXPECT_LT((back - xi).norm(), 1e-14 * (1 + xi.norm()) + 1e-12 * xi.norm());
    }
  }
}

TYPED_TEST(GroupTest, ComposeAndInverseAreMatrixProducts) {
  using G = TypeParam;
  for (int trial = 0; trial < 20; ++trial) {
    const auto a = G::template exp<double>(this->random_tangent(2.0));
    const auto b = G::template exp<double>(this->random_tangent(trial % 2 ? 1e-8 : 2.0));
    const auto Ma = G::matrix(a), Mb = G::matrix(b);
    EXPECT_LT((G::matrix(G::compose(a, b)) - Ma * Mb).norm(), 1e-13);
    EXPECT_LT((G::matrix(G::inverse(a)) - Ma.inverse()).norm(), 1e-13);
    const auto e = G::compose(a, G::inverse(a));
    EXPECT_LT(G::log(e).norm(), 1e-14);
  }
}

TYPED_TEST(GroupTest, AdIsConjugation) {
  using G = TypeParam;
  for (int trial = 0; trial < 20; ++trial) {
    const auto g = G::template exp<double>(this->random_tangent(2.0));
    const auto xi = this->random_tangent(1.0);
    const auto M = G::matrix(g);
    const auto lhs = G::hat(G::Ad(g) * xi);
    const auto rhs = (M * G::hat(xi) * M.inverse()).eval();
    EXPECT_LT((lhs - rhs).norm(), 1e-13);
    // Ad is a homomorphism: Ad_{ab} = Ad_a Ad_b.
    const auto b = G::template exp<double>(this->random_tangent(2.0));
    EXPECT_LT((G::Ad(G::compose(g, b)) - G::Ad(g) * G::Ad(b)).norm(), 1e-13);
  }
}

TYPED_TEST(GroupTest, AutodiffThroughExpAndLogAgreesWithFiniteDifferences) {
  using G = TypeParam;
  constexpr int d = G::dim;
  using T = Dual<double, d>;
  for (double scale : {0.0, 1e-6, 0.45, 0.55, 2.0}) {  // both sides of the series radius
    const auto g = G::template exp<double>(this->random_tangent(1.5));
    const auto xi0 = this->random_tangent(scale);
    // f(ξ) = log(g exp(ξ)), derivative by AD and by central differences.
    typename G::template Tangent<T> xi;
    for (int i = 0; i < d; ++i) xi(i) = T::variable(xi0(i), i);
    const auto f = G::log(G::compose(G::template cast<T>(g), G::template exp<T>(xi)));
    for (int j = 0; j < d; ++j) {
      const double eps = 1e-6;
      auto plus = xi0, minus = xi0;
      plus(j) += eps;
      minus(j) -= eps;
      const auto fd = ((G::log(G::compose(g, G::template exp<double>(plus))) -
                        G::log(G::compose(g, G::template exp<double>(minus)))) /
                       (2 * eps))
                          .eval();
      for (int i = 0; i < d; ++i) EXPECT_NEAR(f(i).d[j], fd(i), 1e-8) << "scale " << scale;
    }
  }
}

TEST(GroupSeries, SeriesAndClosedFormsMeetSmoothlyAtTheRadius) {
  using T = Dual<Dual<double, 1>, 1>;
  for (double w0 : {detail::kSeriesRadius * (1 - 1e-12), detail::kSeriesRadius * (1 + 1e-12)}) {
    const T w = T::variable(Dual<double, 1>::variable(w0, 0), 0);
    const T s = detail::sinc(w), c = detail::cosc(w);
    EXPECT_NEAR(s.v.v, std::sin(w0) / w0, 1e-16);
    EXPECT_NEAR(s.d[0].v, (w0 * std::cos(w0) - std::sin(w0)) / (w0 * w0), 1e-14);
    EXPECT_NEAR(c.v.v, (1 - std::cos(w0)) / w0, 1e-16);
    EXPECT_NEAR(c.d[0].v, (w0 * std::sin(w0) - (1 - std::cos(w0))) / (w0 * w0), 1e-14);
    // Second derivative of sinc: -sin/w - 2cos/w^2 + 2 sin/w^3.
    EXPECT_NEAR(s.d[0].d[0], -std::sin(w0) / w0 - 2 * std::cos(w0) / (w0 * w0) + 2 * std::sin(w0) / std::pow(w0, 3),
                1e-13);
  }
}

namespace {
// The terms j = n .. 14 of Σ_j c_j w^(2j), k-th derivative, in long double (the coefficients
// (-1)^j / (2j + 1 + shift)! to j = 14; their absolute values for a bound).
long double series_tail(int shift, int n, int k, long double a, bool bound = true) {
  long double sum = 0;
  for (int j = n; j < 15; ++j) {
    if (2 * j < k) continue;
    long double c = 1;
    for (int i = 2; i <= 2 * j + 1 + shift; ++i) c /= i;
    if (!bound && j % 2 == 1) c = -c;
    long double falling = 1;
    for (int i = 0; i < k; ++i) falling *= 2 * j - i;
    sum += c * falling * std::pow(a, static_cast<long double>(2 * j - k));
  }
  return sum;
}

template <int K>
void expect_fewest_terms_to_roundoff(int shift) {
  double c[detail::kSeriesTerms];
  for (int j = 0; j < detail::kSeriesTerms; ++j) c[j] = detail::series_coefficient(j, shift);
  const detail::SeriesRadii<K> radii(c);
  auto worst_tail = [&](int n, long double a) {
    long double worst = 0;
    for (int k = 0; k <= K; ++k) worst = std::max(worst, series_tail(shift, n, k, a));
    return worst;
  };
  for (int i = 0; i < 1000; ++i) {
    const double a = i < 20 ? std::pow(10.0, -19 + i) : (i - 20) / 980.0;  // 1e-19 .. 1, then 0 .. 1
    const int n = radii.terms(a);
    SCOPED_TRACE(testing::Message() << "K " << K << ", shift " << shift << ", |w| " << a << ", terms " << n);
    ASSERT_GE(n, 1);
    ASSERT_LE(n, detail::kSeriesTerms);
    if (n < detail::kSeriesTerms) EXPECT_LE(worst_tail(n, a), 1.1e-18L);  // the radii omit j >= 10: +0.1%
    if (n > 1) EXPECT_GT(worst_tail(n - 1, a), 0.9e-18L);  // no term is wasted
    // The series in Poly<K> (Taylor coefficients f^(k) / k!) against the long double sum.
    const Poly<K> p = detail::alternating_series(Poly<K>::variable(a), shift);
    long double fact = 1;
    for (int k = 0; k <= K; ++k) {
      if (k > 0) fact *= k;
      EXPECT_NEAR(p.a[k], static_cast<double>(series_tail(shift, 0, k, a, false) / fact), 4e-16) << "derivative " << k;
    }
  }
}
}  // namespace

// The sinc-type series keep, at each |w|, the fewest terms whose omission costs each carried
// derivative at most 1e-18: too few would fail the first check, too many the second.
TEST(GroupSeries, SeriesKeepTheFewestTermsThatReachRoundoffInEveryDerivative) {
  for (int shift = 0; shift <= 2; ++shift) {
    expect_fewest_terms_to_roundoff<0>(shift);
    expect_fewest_terms_to_roundoff<1>(shift);
    expect_fewest_terms_to_roundoff<2>(shift);
    expect_fewest_terms_to_roundoff<3>(shift);
    expect_fewest_terms_to_roundoff<4>(shift);
    expect_fewest_terms_to_roundoff<5>(shift);
  }
}

TEST(GroupSeries, WrapAngle) {
  EXPECT_NEAR(detail::wrap_angle(3 * M_PI + 0.1), -M_PI + 0.1, 1e-14);
  EXPECT_NEAR(detail::wrap_angle(-0.2), -0.2, 0.0);
  EXPECT_NEAR(detail::wrap_angle(-M_PI), M_PI, 1e-15);
}
