// Rank and conditioning of a shooting Jacobian at a solution (METHOD.md §5): a Jacobian that is
// rank deficient means redundant or inconsistent boundary data (e.g. conserved momenta
// prescribed at both ends); the left null vectors name the dependent conditions.
//
// Two versions: the structured one (sparse QR and LU: memory and work grow with the number of
// nonzeros, as the shooting Jacobian's block bidiagonal pattern allows), which the solver uses,
// and the dense one (column-pivoted QR, SVD), its oracle on small systems.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <string>
#include <vector>

namespace lpshoot {

struct RankDiagnosis {
  int rank = 0;
  double condition = 0;                           // 1-norm estimate of the equilibrated Jacobian
  std::vector<std::string> dependent_conditions;  // one per rank deficit
  std::vector<double> singular_values;            // when deficient
};

// Dense version. J is equilibrated (rows and columns to unit max-norm) before the rank decision;
// `names` names the rows. Rank by column-pivoted QR; the SVD only when the rank is deficient.
RankDiagnosis diagnose_rank(Eigen::MatrixXd J, const std::vector<std::string>& names, double tolerance);

// Structured version, for a sparse J: the same equilibration; the condition by Hager's 1-norm
// estimate on a sparse LU; the rank by sparse QR, run only when the condition allows a
// deficiency; the dependent conditions from the trailing columns of Q. Singular values (a dense
// SVD) only for systems of at most `svd_limit` unknowns. (diagnostics.cpp gives the details.)
RankDiagnosis diagnose_rank(Eigen::SparseMatrix<double, Eigen::ColMajor, int> J, const std::vector<std::string>& names,
                            double tolerance, int svd_limit = 500);

}  // namespace lpshoot
