// LU with partial pivoting of a banded matrix (LAPACK's dgbtf2 / dgbtrs, unblocked), for the
// shooting Jacobian's diagnostics (diagnostics.cpp): the Jacobian is block banded (segment i's
// columns meet the rows of continuity i-1 and i only), so with kl sub- and ku super-diagonals
// the factorization costs O(n kl (kl + ku)) and O(n (2 kl + ku)) memory, where a general sparse
// LU spends most of its time ordering and in supernode bookkeeping.
//
// Storage as LAPACK's band format: A(i, j) at ab(kl + ku + i - j, j); pivoting widens the upper
// band of U to kl + ku, the first kl rows hold that fill.
#pragma once

#include "huge_pages.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace lpshoot {

class BandLU {
 public:
  // Lower and upper bandwidths of a sparse matrix's pattern.
  static std::pair<int, int> bandwidths(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& A) {
    int kl = 0, ku = 0;
    for (int c = 0; c < A.outerSize(); ++c)
      for (Eigen::SparseMatrix<double, Eigen::ColMajor, int>::InnerIterator it(A, c); it; ++it) {
        kl = std::max(kl, static_cast<int>(it.row()) - c);
        ku = std::max(ku, c - static_cast<int>(it.row()));
      }
    return {kl, ku};
  }

  // Whether band storage, (2 kl + ku + 1) n with pivoting's fill, is within 8 times the stored
  // entries: the rule by which the diagnosis (diagnostics.cpp) and KINSOL (kinsol_backend.cpp)
  // take the band LU over a sparse one. The Galerkin electron's Jacobian at N = 10⁶ (explicit
  // zeros pruned: 7.9 entries per column in a band of 42) passes it: its band LU takes 47 ms
  // where Eigen's sparse LU took 90 ms and KLU ~120 ms.
  static bool pays(long n, int kl, int ku, long nonzeros) {
    return kl >= 0 && ku >= 0 && static_cast<double>(2 * kl + ku + 1) * n <= 8.0 * static_cast<double>(nonzeros) + n;
  }

  // Factors the square A with bandwidths (kl, ku). ok() is false when a pivot is exactly zero
  // (A singular): no solve is then possible.
  BandLU(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& A, int kl, int ku)
      : n_(static_cast<int>(A.cols())), kl_(kl), ku_(ku), ab_(2 * kl + ku + 1, A.cols()), pivot_(A.cols()) {
    advise_huge_pages(ab_.data(), static_cast<std::size_t>(ab_.size()) * sizeof(double));  // before the first touch
    ab_.setZero();
    for (int c = 0; c < A.outerSize(); ++c)
      for (Eigen::SparseMatrix<double, Eigen::ColMajor, int>::InnerIterator it(A, c); it; ++it)
        at(static_cast<int>(it.row()), c) = it.value();
    for (int j = 0; j < n_; ++j) {
      const int below = std::min(kl_, n_ - 1 - j);
      int p = 0;
      for (int i = 1; i <= below; ++i)
        if (std::abs(at(j + i, j)) > std::abs(at(j + p, j))) p = i;
      pivot_[j] = j + p;
      if (at(j + p, j) == 0.0) {
        ok_ = false;
        return;
      }
      const int last = std::min(j + kl_ + ku_, n_ - 1);  // the columns row j reaches after pivoting
      if (p != 0)
        for (int c = j; c <= last; ++c) std::swap(at(j, c), at(j + p, c));
      const double inv = 1.0 / at(j, j);
      for (int i = 1; i <= below; ++i) at(j + i, j) *= inv;
      for (int c = j + 1; c <= last; ++c) {
        const double f = at(j, c);
        if (f != 0.0)
          for (int i = 1; i <= below; ++i) at(j + i, c) -= at(j + i, j) * f;
      }
    }
  }

  bool ok() const { return ok_; }

  // A x = b.
  Eigen::VectorXd solve(Eigen::VectorXd b) const {
    for (int j = 0; j < n_; ++j) {  // L: row swaps and eliminations in factorization order
      std::swap(b(j), b(pivot_[j]));
      const int below = std::min(kl_, n_ - 1 - j);
      for (int i = 1; i <= below; ++i) b(j + i) -= at(j + i, j) * b(j);
    }
    for (int j = n_ - 1; j >= 0; --j) {  // U
      b(j) /= at(j, j);
      for (int i = std::max(0, j - kl_ - ku_); i < j; ++i) b(i) -= at(i, j) * b(j);
    }
    return b;
  }

  // A^T x = b: U^T, then L^T with the swaps in reverse order.
  Eigen::VectorXd solve_transposed(Eigen::VectorXd b) const {
    for (int j = 0; j < n_; ++j) {
      double s = b(j);
      for (int i = std::max(0, j - kl_ - ku_); i < j; ++i) s -= at(i, j) * b(i);
      b(j) = s / at(j, j);
    }
    for (int j = n_ - 1; j >= 0; --j) {
      const int below = std::min(kl_, n_ - 1 - j);
      for (int i = 1; i <= below; ++i) b(j) -= at(j + i, j) * b(j + i);
      std::swap(b(j), b(pivot_[j]));
    }
    return b;
  }

 private:
  double& at(int i, int j) { return ab_(kl_ + ku_ + i - j, j); }
  double at(int i, int j) const { return ab_(kl_ + ku_ + i - j, j); }

  int n_, kl_, ku_;
  Eigen::MatrixXd ab_;
  std::vector<int> pivot_;
  bool ok_ = true;
};

}  // namespace lpshoot
