// A square nonlinear system F(x) = 0 with an exact Jacobian, and the solver backends behind one
// interface: SUNDIALS KINSOL (Newton with line search, fresh Jacobian every iteration unless F is
// affine) and NLopt
// (SLSQP with the equations as equality constraints). The C libraries stay in the .cpp files.
// Jacobians are sparse (a shooting Jacobian is block bidiagonal): KINSOL factors them with
// KLU, so that memory and work grow like the number of segments, not its square or cube.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <string>
#include <vector>

namespace lpshoot {

// Column major: the layout of KLU's compressed sparse columns.
using SparseJacobian = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

class NonlinearSystem {
 public:
  virtual ~NonlinearSystem() = default;
  virtual int size() const = 0;
  // Returns false when F cannot be evaluated at x (the flow failed): solvers then shorten the step.
  virtual bool residual(const Eigen::VectorXd& x, Eigen::VectorXd& F) = 0;
  // The pattern should not change between calls (explicit zeros are fine): KINSOL's KLU
  // reuses its symbolic analysis, and analyses again when the pattern changes.
  virtual bool jacobian(const Eigen::VectorXd& x, SparseJacobian& J) = 0;
  // The norm that judges progress (divergence) of full Newton steps, as opposed to convergence:
  // a system whose rows are scaled for the stopping test (e.g. by per-row tolerances) returns
  // the norm of the unscaled rows here.
  virtual double progress_norm(const Eigen::VectorXd& F) const { return F.lpNorm<Eigen::Infinity>(); }
  // A hint from the solver: the Jacobian will be asked for at the point of the next residual
  // evaluation (a full Newton step that will not converge there). A system that gets both from
  // one sweep (shooting: one flow with sensitivities instead of one without, then one with) may
  // compute it with the residual. Ignored by default.
  virtual void expect_jacobian(bool) {}
  // The Jacobian's pattern as known before the solve (its lower and upper bandwidths and stored
  // entries), for the choice of a band or a sparse factorization; kl < 0: unknown.
  struct Pattern {
    int kl = -1, ku = -1;
    long nonzeros = 0;
  };
  virtual Pattern pattern() const { return {}; }
};

enum class Backend { Kinsol, Nlopt };

// KINSOL's linear solver: Auto takes the band LU for a banded pattern (NonlinearSystem::pattern),
// else KLU; Band and Klu force one (Band needs the pattern).
enum class LinearSolver { Auto, Band, Klu };

struct SolverOptions {
  Backend backend = Backend::Kinsol;
  double tolerance = 1e-10;  // max-norm of F at a solution
  int max_iterations = 50;
  // Called at each Jacobian evaluation (one per iteration) with the iteration number (1, 2, ...)
  // and the max-norm of F there: for progress displays. Must not throw.
  std::function<void(int, double)> on_iteration;
  // F is affine in x (its Jacobian is the same everywhere: a problem without a group whose
  // Lagrangian is quadratic and constraints linear, core/degree.hpp). KINSOL then factors the
  // Jacobian once, and its later full Newton steps, on that factorization, are exact Newton steps.
  bool affine = false;
  LinearSolver linear_solver = LinearSolver::Auto;
  // The caller has a cheaper remedy than a long line search (shooting: more segments,
  // ShootingOptions::segment_doublings): KINSOL's line search then stops when it crawls, its
  // residual falling less than 2-fold over 5 iterations (the spherical pendulum's windows on one
  // 80-step segment: 2.2e9 to 5.8e8 tolerances in 47 iterations). NLopt ignores it.
  bool stop_when_crawling = false;
};

enum class SolverStatus { Converged, NotConverged, Failed };

struct SolverOutcome {
  SolverStatus status = SolverStatus::NotConverged;
  std::string message;
  int iterations = 0;
  std::vector<double> residual_history;  // max-norm of F at each accepted iterate
  double residual_norm = 0;
  // Not converged: full Newton steps stopped at the noise of F within 100x the tolerance, after
  // cutting it at least a thousandfold (KINSOL; shooting: the flows' roundoff floor).
  bool stalled_at_noise = false;
};

// Solves F(x) = 0 from x (updated in place).
SolverOutcome solve_nonlinear(NonlinearSystem& system, Eigen::VectorXd& x, const SolverOptions& options);

const char* backend_name(Backend b);

// "1.23e-09"
std::string format_residual(double x);

}  // namespace lpshoot
