// Rank and conditioning of a shooting Jacobian at a solution (METHOD.md §5): a Jacobian that is
// rank deficient means redundant or inconsistent boundary data (e.g. conserved momenta
// prescribed at both ends); the left null vectors name the dependent conditions.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace lpshoot {

struct RankDiagnosis {
  int rank = 0;
  double condition = 0;                           // 1-norm estimate of the equilibrated Jacobian
  std::vector<std::string> dependent_conditions;  // one per rank deficit
  std::vector<double> singular_values;            // when deficient
};

// J is equilibrated (rows and columns to unit max-norm) before the rank decision; `names` names
// the rows. Rank by column-pivoted QR; the SVD only when the rank is deficient.
inline RankDiagnosis diagnose_rank(Eigen::MatrixXd J, const std::vector<std::string>& names, double tolerance) {
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
  for (int c = out.rank; c < sv.size(); ++c) {  // left null vectors: dependent conditions
    // The (at most four) largest weights of the left null vector name the dependent rows.
    const Eigen::VectorXd u = svd.matrixU().col(c);
    std::vector<int> rows;
    for (int i = 0; i < u.size(); ++i)
      if (std::abs(u(i)) > 0.1) rows.push_back(i);
    std::sort(rows.begin(), rows.end(), [&](int a, int b) { return std::abs(u(a)) > std::abs(u(b)); });
    std::string dep;
    for (size_t j = 0; j < rows.size() && j < 4; ++j)
      dep += (j ? " + " : "") + std::to_string(u(rows[j])).substr(0, 6) + "·[" + names[rows[j]] + "]";
    if (rows.size() > 4) dep += " + ...";
    out.dependent_conditions.push_back(dep);
  }
  return out;
}

}  // namespace lpshoot
