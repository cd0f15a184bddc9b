// Structured linear algebra (issue 9): the shooting Jacobian is kept sparse and factored by
// KINSOL's KLU; the rank diagnosis runs on sparse QR and a band (or sparse) LU. Checked against
// dense LU, QR and SVD of the same matrices: Newton steps of real shooting systems (groups,
// constraints, single and multiple shooting), ranks, dependent conditions and condition estimates.
#include "oracles/continuous.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>
#include <lpshoot/shooting/band_lu.hpp>
#include <lpshoot/shooting/banded_qr.hpp>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseQR>

#include <gtest/gtest.h>

#include <limits>
#include <random>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {

// F(x) = J0 (x - x0) + F0: Newton's method solves it in one step, x0 - J0^{-1} F0, through
// KINSOL's band or sparse direct solver.
struct Linearized : NonlinearSystem {
  SparseJacobian J0;
  Eigen::VectorXd x0, F0;
  Pattern pattern() const override {
    const auto [kl, ku] = BandLU::bandwidths(J0);
    return {kl, ku, static_cast<long>(J0.nonZeros())};
  }
  int size() const override { return static_cast<int>(J0.rows()); }
  bool residual(const Eigen::VectorXd& x, Eigen::VectorXd& F) override {
    F = J0 * (x - x0) + F0;
    return true;
  }
  bool jacobian(const Eigen::VectorXd&, SparseJacobian& J) override {
    J = J0;
    return true;
  }
};

// The Newton step of `sys` at a random point near the guess (rows scaled by their tolerances, as
// the solver sees them), by KINSOL (KLU, and the band LU) against a reference (dense LU refined
// in long double).
// A backward-stable solve errs by a small multiple of u κ, κ Skeel's condition of the system at
// its solution, | |J^{-1}| |J| |dx| | / |dx| (invariant to row scaling). Expects KLU's error
// within 10 u κ, and within 10 times dense partial-pivoting LU's where that is above u κ (both
// errors are roundings at the u κ level: on the beanie's 3 segments, κ = 6.7e4, KLU gave 1.5e-12
// or 1.4e-11 and dense LU 1.2e-12 or 3.1e-13 with row tolerances differing in the last bits).
template <class X>
double newton_step_difference(detail::ShootingSystem<X>& sys, unsigned seed, const char* what) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  Linearized lin;
  lin.x0.resize(sys.size());
  for (int i = 0; i < lin.x0.size(); ++i) lin.x0(i) = 1e-3 * n01(rng);
  sys.set_row_scaling(sys.row_tolerances(lin.x0, 1e-10).cwiseInverse());
  EXPECT_TRUE(sys.residual(lin.x0, lin.F0) && sys.jacobian(lin.x0, lin.J0));
  const Eigen::MatrixXd dense(lin.J0);
  const Eigen::VectorXd step_dense = -dense.partialPivLu().solve(lin.F0);
  // The reference step: dense LU refined twice with residuals in long double.
  Eigen::VectorXd step = step_dense;
  for (int refinement = 0; refinement < 2; ++refinement) {
    Eigen::VectorXd r(step.size());
    for (int i = 0; i < r.size(); ++i) {
      long double acc = lin.F0(i);
      for (int j = 0; j < r.size(); ++j) acc += static_cast<long double>(dense(i, j)) * step(j);
      r(i) = static_cast<double>(acc);
    }
    step -= dense.partialPivLu().solve(r);
  }
  const double kappa = (dense.inverse().cwiseAbs() * (dense.cwiseAbs() * step.cwiseAbs())).lpNorm<Eigen::Infinity>() /
                       step.lpNorm<Eigen::Infinity>();
  const double dd = (step_dense - step).lpNorm<Eigen::Infinity>() / step.lpNorm<Eigen::Infinity>();
  double worst = 0;
  for (LinearSolver ls : {LinearSolver::Klu, LinearSolver::Band}) {
    Eigen::VectorXd x = lin.x0;
    SolverOptions opt;
    opt.linear_solver = ls;
    // What one exact step leaves: the rounding of J dx + F.
    opt.tolerance = 64 * std::numeric_limits<double>::epsilon() * (dense.cwiseAbs() * step_dense.cwiseAbs()).maxCoeff();
    opt.max_iterations = 3;
    const SolverOutcome out = solve_nonlinear(lin, x, opt);
    const char* name = ls == LinearSolver::Klu ? "KLU" : "band LU";
    EXPECT_EQ(out.status, SolverStatus::Converged) << what << ", " << name << ": " << out.message;
    EXPECT_GE(out.iterations, 1);
    EXPECT_LE(out.iterations, 2);  // a second step may refine the first's rounding
    const double d = ((x - lin.x0) - step).lpNorm<Eigen::Infinity>() / step.lpNorm<Eigen::Infinity>();
    std::printf("%s, %d unknowns: relative error of the step, %s %.2e, dense LU %.2e (Skeel condition %.2e)\n", what,
                sys.size(), name, d, dd, kappa);
    EXPECT_LT(d, 10 * std::numeric_limits<double>::epsilon() * kappa) << what << ", " << name;
    EXPECT_LT(d, 10 * std::max(dd, std::numeric_limits<double>::epsilon() * kappa) + 1e-15) << what << ", " << name;
    worst = std::max(worst, d);
  }
  // The system reports the pattern it evaluates (KINSOL's choice of the band LU rests on it).
  const auto p = sys.pattern();
  const auto [kl, ku] = BandLU::bandwidths(lin.J0);
  EXPECT_EQ(p.kl, kl);
  EXPECT_EQ(p.ku, ku);
  EXPECT_EQ(p.nonzeros, lin.J0.nonZeros());
  return worst;
}

std::vector<int> even_starts(int first, int last, int S) {
  std::vector<int> starts;
  for (int i = 0; i <= S; ++i) starts.push_back(first + static_cast<int>(std::lround(double(last - first) * i / S)));
  return starts;
}

// Rows and columns to unit max-norm, as both diagnoses do first.
Eigen::MatrixXd equilibrated(Eigen::MatrixXd J) {
  for (int r = 0; r < J.rows(); ++r) J.row(r) /= J.row(r).lpNorm<Eigen::Infinity>();
  for (int c = 0; c < J.cols(); ++c) J.col(c) /= J.col(c).lpNorm<Eigen::Infinity>();
  return J;
}

// A random block-bidiagonal matrix of S blocks of size n with boundary rows (the shape of a
// shooting Jacobian): b initial rows on the first block, n - b terminal rows on the last.
Eigen::MatrixXd block_bidiagonal(int S, int n, int b, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(S * n, S * n);
  auto fill = [&](int r0, int c0, int rows, int cols) {
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) J(r0 + r, c0 + c) = u(rng);
  };
  fill(0, 0, b, n);
  for (int i = 0; i + 1 < S; ++i) {
    fill(b + i * n, i * n, n, n);
    J.block(b + i * n, (i + 1) * n, n, n) = -Eigen::MatrixXd::Identity(n, n);
  }
  fill(b + (S - 1) * n, (S - 1) * n, n - b, n);
  return J;
}

std::vector<std::string> row_names(int m) {
  std::vector<std::string> names;
  for (int i = 0; i < m; ++i) names.push_back("row " + std::to_string(i));
  return names;
}

}  // namespace

TEST(StructuredSolve, NewtonStepsAgreeWithDenseLUWithGroupsConstraintsAndSegments) {
  // The beanie (SE(2) x S^1 group, nonholonomic constraints, second-order closure) and the
  // electron, single and multiple shooting.
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  BeanieBoundary s, e;
  s.psi = 0.1, s.psi_dot = 0.3, s.theta = 0.2, s.x = 0.5, s.y = -0.3, s.Omega1 = 0.5, s.Omega2 = 0.2;
  e.psi = 1.0, e.psi_dot = -0.2, e.theta = 1.4, e.x = 1.0, e.y = 0.4;
  // (Its single-shooting Jacobian in these unknowns is singular to working precision, Skeel
  // condition ~1e16 at N = 16 and 60: no step to compare; the electron covers single shooting.)
  for (int S : {3, 12}) {
    const int N = 60;
    const auto bvp = beanie_bvp(b, 1.5, N, s, e, Closure::SecondOrder);
    const auto guess = beanie_guess(bvp, s, e);
    const auto g = reconstruct_group(b, guess.trajectory, guess.g0);
    const auto starts = even_starts(2, N - 1, S);
    std::vector<BoundaryState<BeanieControl>> refs;
    for (int i = 0; i < S; ++i) refs.push_back({guess.trajectory.state(starts[i]), g[starts[i] - 2]});
    detail::ShootingSystem<BeanieControl> sys(bvp, refs, starts, NewtonOptions{}, 1);
    newton_step_difference(sys, 7 + S, ("beanie, " + std::to_string(S) + " segments").c_str());
  }
  const Electron el{};
  const ElectronBoundary a{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
  const ElectronBoundary z{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};
  const auto ebvp = electron_bvp(el, 2.0, 400, a, z, Closure::SecondOrder);
  const auto eguess = electron_guess(ebvp, a, z);
  for (int S : {1, 16}) {
    const auto starts = even_starts(2, 399, S);
    std::vector<BoundaryState<Electron>> refs;
    for (int i = 0; i < S; ++i) refs.push_back({eguess.trajectory.state(starts[i]), Trivial::identity<double>()});
    detail::ShootingSystem<Electron> sys(ebvp, refs, starts, NewtonOptions{}, 1);
    newton_step_difference(sys, 3 + S, ("electron, " + std::to_string(S) + " segments").c_str());
  }
}

TEST(StructuredDiagnosis, FullRankAndConditionAgreeWithDense) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Eigen::MatrixXd J = block_bidiagonal(12, 6, 2, seed);
    const RankDiagnosis sparse = diagnose_rank(SparseJacobian(J.sparseView()), row_names(J.rows()), 1e-10);
    const RankDiagnosis dense = diagnose_rank(J, row_names(J.rows()), 1e-10);
    EXPECT_EQ(sparse.rank, J.cols());
    EXPECT_EQ(dense.rank, J.cols());
    // Hager's estimate is a lower bound of the exact 1-norm condition, and within a small factor.
    const Eigen::MatrixXd E = equilibrated(J);
    const double exact = E.cwiseAbs().colwise().sum().maxCoeff() * E.inverse().cwiseAbs().colwise().sum().maxCoeff();
    std::printf("seed %u: condition exact %.4e, structured estimate %.4e, dense estimate %.4e\n", seed, exact,
                sparse.condition, dense.condition);
    EXPECT_LE(sparse.condition, exact * (1 + 1e-8));
    EXPECT_GE(sparse.condition, exact / 10);
  }
}

TEST(StructuredDiagnosis, DependentRowsAreFoundAndNamedAsByTheDenseSVD) {
  // Row 71 (the last terminal row) becomes 0.5 row 1 + row 10 - row 40: rank one short, and
  // exactly those four rows make up the left null vector.
  Eigen::MatrixXd J = block_bidiagonal(12, 6, 2, 11);
  const int last = static_cast<int>(J.rows()) - 1;
  J.row(last) = 0.5 * J.row(1) + J.row(10) - J.row(40);
  const auto names = row_names(J.rows());
  const RankDiagnosis sparse = diagnose_rank(SparseJacobian(J.sparseView()), names, 1e-10);
  const RankDiagnosis dense = diagnose_rank(J, names, 1e-10);
  EXPECT_EQ(sparse.rank, last);
  EXPECT_EQ(dense.rank, last);
  EXPECT_FALSE(std::isfinite(sparse.condition) && sparse.condition < 1e12) << sparse.condition;
  ASSERT_EQ(sparse.dependent_conditions.size(), 1u);
  ASSERT_EQ(dense.dependent_conditions.size(), 1u);
  std::printf("structured: %s\ndense:      %s\n", sparse.dependent_conditions[0].c_str(), dense.dependent_conditions[0].c_str());
  for (const char* row : {"[row 1]", "[row 10]", "[row 40]", "[row 71]"}) {
    EXPECT_NE(sparse.dependent_conditions[0].find(row), std::string::npos) << row;
    EXPECT_NE(dense.dependent_conditions[0].find(row), std::string::npos) << row;
  }
  // Small systems keep their singular values: one at roundoff, the next far above.
  ASSERT_EQ(sparse.singular_values.size(), J.cols());
  EXPECT_LT(sparse.singular_values.back(), 1e-13 * sparse.singular_values.front());
  EXPECT_GT(sparse.singular_values[J.cols() - 2], 1e-4 * sparse.singular_values.front());
}

TEST(StructuredDiagnosis, NearlyDependentRowsAgreeWithDenseOnBothSidesOfTheTolerance) {
  // The last row moved off a combination of three others by delta e_3: the smallest singular
  // value is ~delta. Below the tolerance (1e-10) both diagnoses find one dependent condition;
  // above it both find full rank: at 1e-8 the sparse QR runs (the condition allows a
  // deficiency) and finds none, at 1e-2 the condition estimate alone shows full rank.
  for (double delta : {1e-12, 1e-8, 1e-2}) {
    Eigen::MatrixXd J = block_bidiagonal(12, 6, 2, 11);
    const int last = static_cast<int>(J.rows()) - 1;
    J.row(last) = 0.5 * J.row(1) + J.row(10) - J.row(40);
    J(last, 3) += delta;
    const auto names = row_names(J.rows());
    const RankDiagnosis sparse = diagnose_rank(SparseJacobian(J.sparseView()), names, 1e-10);
    const RankDiagnosis dense = diagnose_rank(J, names, 1e-10);
    std::printf("delta %.0e: rank structured %d, dense %d, condition %.2e\n", delta, sparse.rank, dense.rank,
                sparse.condition);
    EXPECT_EQ(sparse.rank, dense.rank) << delta;
    EXPECT_EQ(sparse.rank, delta < 1e-10 ? last : last + 1) << delta;
    EXPECT_EQ(sparse.dependent_conditions.size(), delta < 1e-10 ? 1u : 0u) << delta;
  }
}

// The banded QR's rank test (banded_qr.hpp, linear in n) takes the decision of Eigen's SparseQR
// in natural order with the same threshold (the O(n²) factorization it stands in for), on either
// side of the threshold: the last row moved off a combination of three others by delta (the
// smallest singular value ~delta), a row made exactly dependent, and a matrix whose first column
// is already triangular. A banded QR that always said "full rank" would miss the deficient ones;
// one that never did would disagree on the others.
TEST(StructuredDiagnosis, BandedQRDecidesTheRankAsSparseQR) {
  using Sparse = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  int deficient = 0, full = 0;
  for (unsigned seed : {3u, 11u, 29u})
    for (double delta : {0.0, 1e-13, 1e-11, 1e-9, 1e-7, 1e-2}) {
      Eigen::MatrixXd J = block_bidiagonal(20, 6, 2, seed);
      const int last = static_cast<int>(J.rows()) - 1;
      J.row(last) = 0.5 * J.row(1) + J.row(10) - J.row(40);
      J(last, 3) += delta;
      const Sparse E = Sparse(equilibrated(J).sparseView());
      const auto [kl, ku] = BandLU::bandwidths(E);
      Eigen::SparseQR<Sparse, Eigen::NaturalOrdering<int>> qr;
      qr.setPivotThreshold(1e-10);
      qr.compute(E);
      ASSERT_EQ(qr.info(), Eigen::Success);
      const bool sparse_full = qr.rank() == E.cols();
      EXPECT_EQ(banded_qr_full_rank(E, kl, ku, 1e-10), sparse_full) << "seed " << seed << ", delta " << delta;
      (sparse_full ? full : deficient) += 1;
    }
  EXPECT_GT(deficient, 0);  // both sides were exercised
  EXPECT_GT(full, 0);
  // A first column with a single entry (no reflection) and a bandwidth too small for J.
  Eigen::MatrixXd T = block_bidiagonal(4, 3, 1, 7);
  T.col(0).setZero();
  T(0, 0) = 2.0;
  const Sparse S = Sparse(T.sparseView());
  const auto [kl, ku] = BandLU::bandwidths(S);
  EXPECT_TRUE(banded_qr_full_rank(S, kl, ku, 1e-10));
  EXPECT_FALSE(banded_qr_full_rank(S, kl - 1, ku, 1e-10)) << "an entry outside the band given";
}

TEST(StructuredDiagnosis, NonFiniteEntriesHaveNoRank) {
  Eigen::MatrixXd J = block_bidiagonal(3, 4, 2, 5);
  J(3, 2) = NAN;
  const RankDiagnosis d = diagnose_rank(SparseJacobian(J.sparseView()), row_names(J.rows()), 1e-10);
  EXPECT_EQ(d.rank, -1);
  EXPECT_FALSE(std::isfinite(d.condition));
}

// The band LU of the diagnosis (band_lu.hpp) against dense LU: solves with A and A^T on a random
// banded matrix whose diagonal is small, so that every column pivots across the band.
TEST(StructuredDiagnosis, BandLUSolvesAsDenseLU) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const int n = 60, kl = 5, ku = 3;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = std::max(0, j - ku); i <= std::min(n - 1, j + kl); ++i) A(i, j) = i == j ? 1e-3 * U(rng) : U(rng);
  const SparseJacobian As(A.sparseView());
  const auto [bl, bu] = BandLU::bandwidths(As);
  EXPECT_EQ(bl, kl);
  EXPECT_EQ(bu, ku);
  const BandLU lu(As, bl, bu);
  ASSERT_TRUE(lu.ok());
  const Eigen::PartialPivLU<Eigen::MatrixXd> dense(A);
  const double kappa = A.lpNorm<1>() * dense.inverse().lpNorm<1>();
  for (int k = 0; k < 3; ++k) {
    const Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(n, [&] { return U(rng); });
    const Eigen::VectorXd x = dense.solve(b), xt = dense.transpose().solve(b);
    // Both backward stable: they differ by a small multiple of u κ.
    const double bound = 100 * std::numeric_limits<double>::epsilon() * kappa;
    EXPECT_LE((lu.solve(b) - x).norm() / x.norm(), bound) << "kappa " << kappa;
    EXPECT_LE((lu.solve_transposed(b) - xt).norm() / xt.norm(), bound) << "kappa " << kappa;
    EXPECT_LE((A * lu.solve(b) - b).norm() / b.norm(), 1e-12);
    EXPECT_LE((A.transpose() * lu.solve_transposed(b) - b).norm() / b.norm(), 1e-12);
  }
  Eigen::MatrixXd S = A;
  S.col(7).setZero();  // exactly singular: a zero pivot
  EXPECT_FALSE(BandLU(SparseJacobian(S.sparseView()), kl, ku).ok());
}
