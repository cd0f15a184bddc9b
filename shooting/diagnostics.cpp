// Rank and conditioning of a shooting Jacobian (diagnostics.hpp). Compiled once here: Eigen's
// dense and sparse factorizations cost ~40 s of compilation in every file that would include them.
#include "diagnostics.hpp"

#include "band_lu.hpp"
#include "banded_qr.hpp"

#include <lpshoot/core/one_norm_estimate.hpp>

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/OrderingMethods>
#include <Eigen/SVD>
#include <Eigen/SparseLU>
#include <Eigen/SparseQR>

#include <algorithm>
#include <cmath>

namespace lpshoot {

namespace {
// A left null vector u (unit 2-norm) as its (at most four) largest weights on the named rows:
// "0.7071·[terminal theta] + -0.707·[terminal psi]".
std::string name_dependent(const Eigen::VectorXd& u, const std::vector<std::string>& names) {
  std::vector<int> rows;
  for (int i = 0; i < u.size(); ++i)
    if (std::abs(u(i)) > 0.1) rows.push_back(i);
  std::sort(rows.begin(), rows.end(), [&](int a, int b) { return std::abs(u(a)) > std::abs(u(b)); });
  std::string dep;
  for (size_t j = 0; j < rows.size() && j < 4; ++j)
    dep += (j ? " + " : "") + std::to_string(u(rows[j])).substr(0, 6) + "·[" + names[rows[j]] + "]";
  if (rows.size() > 4) dep += " + ...";
  return dep;
}

}  // namespace

// Dense version. J is equilibrated (rows and columns to unit max-norm) before the rank decision; `names` names
// the rows. Rank by column-pivoted QR; the SVD only when the rank is deficient.
RankDiagnosis diagnose_rank(Eigen::MatrixXd J, const std::vector<std::string>& names, double tolerance) {
  RankDiagnosis out;
  if (!J.allFinite()) {  // the flow overflowed: no rank to speak of
    out.rank = -1;
    out.condition = INFINITY;
    return out;
  }
  for (int r = 0; r < J.rows(); ++r) {
    const double norm = J.row(r).lpNorm<Eigen::Infinity>();
    if (norm > 0) J.row(r) /= norm;
  }
  for (int c = 0; c < J.cols(); ++c) {
    const double norm = J.col(c).lpNorm<Eigen::Infinity>();
    if (norm > 0) J.col(c) /= norm;
  }
  // Entries below 1e-200 of their row and column scale are rounding of an overflowing flow, not
  // data; flushed to zero they keep the factorizations away from subnormal arithmetic (Eigen
  // 3.4's BDCSVD reads outside its arrays on such input).
  J = (J.array().abs() < 1e-200).select(0.0, J);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J);
  const Eigen::VectorXd rdiag = qr.matrixR().diagonal().cwiseAbs();
  for (int i = 0; i < rdiag.size(); ++i)
    if (rdiag(i) > tolerance * rdiag(0)) ++out.rank;
  const double rc = Eigen::PartialPivLU<Eigen::MatrixXd>(J).rcond();
  out.condition = rc > 0 ? 1.0 / rc : INFINITY;
  if (out.rank == J.cols()) return out;
  Eigen::BDCSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinU);
  const auto& sv = svd.singularValues();
  out.singular_values = std::vector<double>(sv.data(), sv.data() + sv.size());
  int rank = 0;
  for (int i = 0; i < sv.size(); ++i)
    if (sv(i) > tolerance * sv(0)) ++rank;
  out.rank = std::min(out.rank, rank);
  for (int c = out.rank; c < sv.size(); ++c) out.dependent_conditions.push_back(name_dependent(svd.matrixU().col(c), names));
  return out;
}


// Structured version, for a sparse J: the same equilibration and flush; the condition by
// Hager's 1-norm estimate on a sparse LU; the rank by sparse QR, when the condition allows a
// deficiency (a column whose remaining norm falls below `tolerance`, i.e. tolerance times the
// unit scale of the equilibrated columns, is rank deficient; natural column order: the shooting
// Jacobian is banded and its Householder vectors stay within the band, where COLAMD's order
// filled Q like S^2 and took 75% of a 4800-unknown solve); the dependent conditions from the
// trailing columns of Q, a basis of the left null space. Singular values (a dense SVD) only for
// systems of at most `svd_limit` unknowns; a larger deficient system gets the dependent
// conditions without them.
RankDiagnosis diagnose_rank(Eigen::SparseMatrix<double, Eigen::ColMajor, int> J, const std::vector<std::string>& names,
                            double tolerance, int svd_limit) {
  using Sparse = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  RankDiagnosis out;
  J.makeCompressed();
  if (!Eigen::Map<const Eigen::VectorXd>(J.valuePtr(), J.nonZeros()).allFinite()) {
    out.rank = -1;
    out.condition = INFINITY;
    return out;
  }
  Eigen::VectorXd rmax = Eigen::VectorXd::Zero(J.rows()), cmax = Eigen::VectorXd::Zero(J.cols());
  for (int c = 0; c < J.outerSize(); ++c)
    for (Sparse::InnerIterator it(J, c); it; ++it) rmax(it.row()) = std::max(rmax(it.row()), std::abs(it.value()));
  for (int c = 0; c < J.outerSize(); ++c)
    for (Sparse::InnerIterator it(J, c); it; ++it) {
      if (rmax(it.row()) > 0) it.valueRef() /= rmax(it.row());
      cmax(c) = std::max(cmax(c), std::abs(it.value()));
    }
  for (int c = 0; c < J.outerSize(); ++c)
    for (Sparse::InnerIterator it(J, c); it; ++it) {
      if (cmax(c) > 0) it.valueRef() /= cmax(c);
      if (std::abs(it.value()) < 1e-200) it.valueRef() = 0;  // as in the dense version
    }
  J.prune(0.0);
  const int n = static_cast<int>(J.cols());
  double norm1 = 0;
  for (int c = 0; c < n; ++c) norm1 = std::max(norm1, J.col(c).cwiseAbs().sum());
  out.condition = INFINITY;
  double inverse_norm1 = INFINITY;
  // A banded J (the shooting Jacobian: block bidiagonal with boundary rows) is factored in band
  // storage (band_lu.hpp: O(n kl (kl + ku)), no ordering step) when BandLU::pays; a wider
  // pattern by sparse LU.
  const auto [kl, ku] = BandLU::bandwidths(J);
  if (BandLU::pays(n, kl, ku, static_cast<long>(J.nonZeros()))) {
    const BandLU lu(J, kl, ku);
    if (lu.ok())
      inverse_norm1 = inverse_one_norm_estimate<Eigen::VectorXd>([&](const Eigen::VectorXd& b) { return lu.solve(b); },
                                                [&](const Eigen::VectorXd& b) { return lu.solve_transposed(b); }, n);
  } else {
    Eigen::SparseLU<Sparse, Eigen::COLAMDOrdering<int>> lu;
    lu.compute(J);
    if (lu.info() == Eigen::Success)
      inverse_norm1 = inverse_one_norm_estimate<Eigen::VectorXd>([&](const Eigen::VectorXd& b) -> Eigen::VectorXd { return lu.solve(b); },
                                                [&](const Eigen::VectorXd& b) -> Eigen::VectorXd { return lu.transpose().solve(b); }, n);
  }
  if (std::isfinite(norm1 * inverse_norm1)) out.condition = norm1 * inverse_norm1;
  // The QR runs only when it can find a deficiency: its test (a column's norm, orthogonalized
  // against the columns before it, below `tolerance`) cannot fire when σ_min(J) > tolerance, and
  // σ_min(J) >= 1 / (√n |J⁻¹|₁). Hager's estimate of |J⁻¹|₁ is a lower bound, within a small
  // factor in practice: with a margin of 100, a J it finds well conditioned is full rank. (Eigen's
  // SparseQR resets work arrays of the full size at every column, O(n²) in all: 14% of an
  // electron solve at N = 10⁶, where the condition is ~1e4.)
  if (std::sqrt(static_cast<double>(n)) * inverse_norm1 * tolerance * 100 < 1) {
    out.rank = n;
    return out;
  }
  // A banded J: the same test by a banded QR first, linear in n (the beanie on Galerkin 4 at
  // N = 10⁶: 2.2e5 unknowns, condition ~2e13, the SparseQR below took 45 s); only a deficiency
  // it finds goes on to the SparseQR, whose Q names the dependent conditions.
  if (BandLU::pays(n, kl, ku, static_cast<long>(J.nonZeros())) && banded_qr_full_rank(J, kl, ku, tolerance)) {
    out.rank = n;
    return out;
  }
  Eigen::SparseQR<Sparse, Eigen::NaturalOrdering<int>> qr;
  qr.setPivotThreshold(tolerance);
  qr.compute(J);
  out.rank = qr.info() == Eigen::Success ? static_cast<int>(qr.rank()) : 0;
  if (out.rank >= n) return out;
  if (n <= svd_limit) {
    const Eigen::MatrixXd dense(J);
    const Eigen::BDCSVD<Eigen::MatrixXd> svd(dense);
    const auto& sv = svd.singularValues();
    out.singular_values = std::vector<double>(sv.data(), sv.data() + sv.size());
  }
  for (int k = out.rank; k < J.rows(); ++k) {  // Q e_k, k >= rank: orthogonal to the range of J
    const Eigen::VectorXd u = qr.matrixQ() * Eigen::VectorXd::Unit(J.rows(), k);
    out.dependent_conditions.push_back(name_dependent(u, names));
  }
  return out;
}

}  // namespace lpshoot
