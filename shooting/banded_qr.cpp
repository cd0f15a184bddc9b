// The banded QR rank test (banded_qr.hpp): column j's reflector spans rows j .. j + kl and
// reaches columns j + 1 .. j + kl + ku (R's upper bandwidth is kl + ku), so each column meets the
// reflectors of the kl + ku columns before it, kept in a ring. Householder vectors and β as in
// Eigen's SparseQR::factorize, so that both take the same decision.
#include "banded_qr.hpp"

#include <algorithm>
#include <cmath>

namespace lpshoot {

bool banded_qr_full_rank(const Eigen::SparseMatrix<double, Eigen::ColMajor, int>& J, int kl, int ku, double threshold) {
  using Sparse = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  const int n = static_cast<int>(J.cols()), up = kl + ku, len = kl + 1, ring = up + 1;
  if (J.rows() != n || kl < 0 || ku < 0) return false;
  Eigen::MatrixXd V = Eigen::MatrixXd::Zero(len, ring);  // reflector k in column k % ring, v(0) = 1
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(ring);
  Eigen::VectorXd col(up + len);  // column j's rows j - up .. j + kl
  for (int j = 0; j < n; ++j) {
    col.setZero();
    for (Sparse::InnerIterator it(J, j); it; ++it) {
      const int at = static_cast<int>(it.row()) - (j - up);
      if (at < 0 || at >= col.size()) return false;  // outside the bandwidths given
      col(at) = it.value();
    }
    for (int k = std::max(0, j - up); k < j; ++k) {  // H_k = I - tau v vᵀ on rows k .. k + kl
      const int rows = std::min(len, n - k), slot = k % ring;
      auto part = col.segment(k - (j - up), rows);
      part -= (tau(slot) * V.col(slot).head(rows).dot(part)) * V.col(slot).head(rows);
    }
    const int rows = std::min(len, n - j), slot = j % ring;
    const auto x = col.segment(up, rows);
    const double c0 = x(0), below = x.tail(rows - 1).squaredNorm();
    double beta = c0;  // as SparseQR: no reflection when the column is already triangular
    tau(slot) = 0;
    if (below > 0) {
      beta = c0 >= 0 ? -std::sqrt(c0 * c0 + below) : std::sqrt(c0 * c0 + below);
      V.col(slot).head(rows) = x / (c0 - beta);
      tau(slot) = (beta - c0) / beta;
    }
    V(0, slot) = 1;
    if (!(std::abs(beta) >= threshold)) return false;
  }
  return true;
}

}  // namespace lpshoot
