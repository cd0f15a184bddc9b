// LU with partial pivoting (PA = LU, LAPACK getrf's row interchanges) of a small fixed-size
// matrix, and the solves a step needs: one right-hand side, many, and with the transpose (Hager's
// condition estimate). Eigen's PartialPivLU sends fixed sizes through its blocked kernels for
// dynamic matrices (gebp, trsm, packing): at the Galerkin 6 beanie step (n = 21, 26 right-hand
// sides) its factorization and many-column solve took 2.0 and 3.3 µs, these loops 1.5 and 1.7 µs
// (bench/RESULTS.md, "Small step matrices"). Same pivots.
// The one-vector solves work on a local array with fully unrolled loops: written through the
// result (or with Eigen's run-time-sized segments) every update went through memory, in a
// serial chain of store-to-load forwarding (7 × 7: 102 against 33 ns; bench/RESULTS.md, "The
// small solves in registers"). The solves multiply by U's diagonal's reciprocals, kept from the
// factorization (a back substitution divided in a serial chain of ~13-cycle latencies; with the
// many-column solve's, ~7% of a beanie paper step with its sensitivity: bench/RESULTS.md, "Window
// Hessians on a tape"): their results differ from Eigen's by rounding, one more per division.
// The factors are Eigen's to rounding (the elimination divides, as Eigen does).
// A zero pivot is kept: its reciprocal is inf, and solves then return inf or NaN, which the
// condition estimate reports as a singular matrix (newton.hpp), as with Eigen's.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <utility>

namespace lpshoot {

template <int n>
class SmallLU {
  static_assert(n > 0, "SmallLU is for fixed sizes");

 public:
  using Matrix = Eigen::Matrix<double, n, n>;
  using Vector = Eigen::Matrix<double, n, 1>;

  // Right-looking elimination on columns: each step is a pivot search (the first largest
  // magnitude, as Eigen's maxCoeff), one row interchange and contiguous column updates below the
  // pivot, on a local array.
  void compute(const Matrix& a) {
    double t[n * n];  // column-major, as lu_
    for (int i = 0; i < n * n; ++i) t[i] = a.data()[i];
    for (int k = 0; k < n; ++k) {
      double* ck = t + k * n;
      int p = k;
      double largest = std::abs(ck[k]);
      for (int i = k + 1; i < n; ++i)
        if (std::abs(ck[i]) > largest) largest = std::abs(ck[i]), p = i;
      pivot_[k] = p;
      if (p != k)
        for (int j = 0; j < n; ++j) std::swap(t[j * n + k], t[j * n + p]);
      const double pivot = ck[k];
      if (pivot != 0)
        for (int i = k + 1; i < n; ++i) ck[i] /= pivot;
      for (int j = k + 1; j < n; ++j) {
        double* cj = t + j * n;
        const double s = cj[k];
        for (int i = k + 1; i < n; ++i) cj[i] -= s * ck[i];
      }
    }
    for (int i = 0; i < n * n; ++i) lu_.data()[i] = t[i];
    for (int i = 0; i < n; ++i) inverse_diagonal_[i] = 1.0 / t[i * n + i];
    for (int i = 0; i < n; ++i) row_[i] = i;
    for (int k = 0; k < n; ++k) std::swap(row_[k], row_[pivot_[k]]);
  }

  // A^{-1} b: the interchanges, then L (unit) and U by column updates.
  Vector solve(const Vector& b) const {
    double t[n];
#pragma GCC unroll 32
    for (int i = 0; i < n; ++i) t[i] = b(row_[i]);
#pragma GCC unroll 32
    for (int k = 0; k < n - 1; ++k)
#pragma GCC unroll 32
      for (int i = k + 1; i < n; ++i) t[i] -= t[k] * lu_(i, k);
#pragma GCC unroll 32
    for (int k = n - 1; k >= 0; --k) {
      t[k] *= inverse_diagonal_[k];
#pragma GCC unroll 32
      for (int i = 0; i < k; ++i) t[i] -= t[k] * lu_(i, k);
    }
    Vector x;
    for (int i = 0; i < n; ++i) x(i) = t[i];
    return x;
  }

  // A^{-1} B for m columns, on Bᵀ: row i of the solution is a combination of rows k < i (then
  // k > i), each a contiguous vector of m, accumulated in place.
  template <int m>
  Eigen::Matrix<double, n, m> solve(const Eigen::Matrix<double, n, m>& b) const {
    Eigen::Matrix<double, m, n> xt = b.transpose();
    for (int k = 0; k < n; ++k)
      if (pivot_[k] != k) xt.col(k).swap(xt.col(pivot_[k]));
    for (int i = 1; i < n; ++i) {
      Eigen::Matrix<double, m, 1> row = xt.col(i);
      for (int k = 0; k < i; ++k) row -= lu_(i, k) * xt.col(k);
      xt.col(i) = row;
    }
    for (int i = n - 1; i >= 0; --i) {
      Eigen::Matrix<double, m, 1> row = xt.col(i);
      for (int k = i + 1; k < n; ++k) row -= lu_(i, k) * xt.col(k);
      xt.col(i) = row * inverse_diagonal_[i];
    }
    return xt.transpose();
  }

  // A^{-T} b = P^T L^{-T} U^{-T} b: Uᵀ then Lᵀ (unit) by column updates with the factors' rows,
  // then the interchanges undone.
  Vector solve_transposed(const Vector& b) const {
    double t[n];
#pragma GCC unroll 32
    for (int i = 0; i < n; ++i) t[i] = b(i);
#pragma GCC unroll 32
    for (int k = 0; k < n; ++k) {
      t[k] *= inverse_diagonal_[k];
#pragma GCC unroll 32
      for (int i = k + 1; i < n; ++i) t[i] -= t[k] * lu_(k, i);
    }
#pragma GCC unroll 32
    for (int k = n - 1; k > 0; --k)
#pragma GCC unroll 32
      for (int i = 0; i < k; ++i) t[i] -= t[k] * lu_(k, i);
    Vector x;
    for (int i = 0; i < n; ++i) x(row_[i]) = t[i];
    return x;
  }

  // L below the diagonal (unit diagonal implied) and U on and above it.
  const Matrix& factors() const { return lu_; }

  // P^T L U, the matrix factored (to rounding).
  Matrix reconstructed() const {
    Matrix a = lu_.template triangularView<Eigen::UnitLower>().toDenseMatrix() * lu_.template triangularView<Eigen::Upper>().toDenseMatrix();
    for (int k = n - 1; k >= 0; --k)
      if (pivot_[k] != k) a.row(k).swap(a.row(pivot_[k]));
    return a;
  }

 private:
  Matrix lu_ = Matrix::Zero();
  std::array<int, n> pivot_{};  // row k was interchanged with row pivot_[k] >= k
  std::array<int, n> row_{};    // row i of PA is row row_[i] of A
  std::array<double, n> inverse_diagonal_{};  // 1 / U(i, i)
};

}  // namespace lpshoot
