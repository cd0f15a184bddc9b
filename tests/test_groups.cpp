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

TEST(GroupSeries, WrapAngle) {
  EXPECT_NEAR(detail::wrap_angle(3 * M_PI + 0.1), -M_PI + 0.1, 1e-14);
  EXPECT_NEAR(detail::wrap_angle(-0.2), -0.2, 0.0);
  EXPECT_NEAR(detail::wrap_angle(-M_PI), M_PI, 1e-15);
}
