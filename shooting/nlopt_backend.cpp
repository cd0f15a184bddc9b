// NLopt backend: SLSQP with F(x) = 0 as equality constraints and a zero objective, so that each
// SQP step is the minimum-norm Newton step of the square system. Exceptions thrown in a callback
// come back from NLopt as a generic failure: they are stored and rethrown. SLSQP is a dense
// method (its quasi-Newton matrix is n x n): the sparse Jacobian is expanded here, so this
// backend suits systems of up to a few thousand unknowns; KINSOL's is the structured one.
#include "nonlinear_solver.hpp"

#include <nlopt.hpp>

#include <cmath>
#include <cstdio>
#include <exception>

namespace lpshoot {
namespace {
struct NloptData {
  NonlinearSystem* system;
  Eigen::VectorXd x, F;
  SparseJacobian J;
  std::exception_ptr error;
  int evaluations = 0, jacobians = 0;
  bool failed = false;
  const SolverOptions* options = nullptr;
  std::vector<double>* history = nullptr;
};

void constraints(unsigned m, double* result, unsigned n, const double* x, double* grad, void* user) {
  auto* d = static_cast<NloptData*>(user);
  try {
    d->x = Eigen::Map<const Eigen::VectorXd>(x, n);
    ++d->evaluations;
    if (!d->system->residual(d->x, d->F) || !d->F.allFinite()) {
      d->failed = true;
      throw nlopt::forced_stop();
    }
    Eigen::Map<Eigen::VectorXd>(result, m) = d->F;
    if (grad) {
      if (!d->system->jacobian(d->x, d->J)) {
        d->failed = true;
        throw nlopt::forced_stop();
      }
      // NLopt wants grad[i * n + j] = dF_i / dx_j (row major).
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(grad, m, n) = Eigen::MatrixXd(d->J);
      const double norm = d->F.lpNorm<Eigen::Infinity>();
      if (++d->jacobians > 1) d->history->push_back(norm);  // the start is recorded before optimize
      if (d->options->on_iteration) d->options->on_iteration(d->jacobians, norm);
    }
  } catch (const nlopt::forced_stop&) {
    throw;
  } catch (...) {
    d->error = std::current_exception();
    throw nlopt::forced_stop();
  }
}

double zero_objective(unsigned n, const double*, double* grad, void*) {
  if (grad) std::fill(grad, grad + n, 0.0);
  return 0.0;
}
}  // namespace

SolverOutcome solve_nlopt(NonlinearSystem& system, Eigen::VectorXd& x, const SolverOptions& opt) {
  SolverOutcome out;
  const int n = system.size();
  NloptData data{&system, x, Eigen::VectorXd(n), SparseJacobian(n, n), nullptr};
  data.options = &opt;
  data.history = &out.residual_history;
  nlopt::opt o(nlopt::LD_SLSQP, n);
  o.set_min_objective(zero_objective, nullptr);
  o.add_equality_mconstraint(constraints, &data, std::vector<double>(n, opt.tolerance * 0.1));
  o.set_xtol_rel(1e-15);
  o.set_maxeval(std::max(1, 4 * opt.max_iterations));
  if (system.residual(x, data.F)) out.residual_history.push_back(data.F.lpNorm<Eigen::Infinity>());
  std::vector<double> xv(x.data(), x.data() + n);
  double f = 0;
  std::string why;
  try {
    const nlopt::result r = o.optimize(xv, f);
    why = "NLopt SLSQP returned code " + std::to_string(static_cast<int>(r));
  } catch (const nlopt::roundoff_limited&) {
    why = "NLopt SLSQP stopped on roundoff";
  } catch (const nlopt::forced_stop&) {
    why = data.failed ? "NLopt SLSQP stopped: the flow failed at a trial point" : "NLopt SLSQP was stopped";
  } catch (const std::exception& e) {
    why = std::string("NLopt SLSQP failed: ") + e.what();
  }
  if (data.error) std::rethrow_exception(data.error);
  x = Eigen::Map<Eigen::VectorXd>(xv.data(), n);
  out.iterations = data.evaluations;
  const bool ok = system.residual(x, data.F);
  out.residual_norm = ok ? data.F.lpNorm<Eigen::Infinity>() : INFINITY;
  out.residual_history.push_back(out.residual_norm);
  if (ok && out.residual_norm <= opt.tolerance) {
    out.status = SolverStatus::Converged;
  } else {
    out.status = SolverStatus::NotConverged;
    out.message = why + " after " + std::to_string(out.iterations) + " evaluations, residual " +
                  format_residual(out.residual_norm);
  }
  return out;
}

SolverOutcome solve_kinsol(NonlinearSystem& system, Eigen::VectorXd& x, const SolverOptions& opt);

SolverOutcome solve_nonlinear(NonlinearSystem& system, Eigen::VectorXd& x, const SolverOptions& opt) {
  return opt.backend == Backend::Kinsol ? solve_kinsol(system, x, opt) : solve_nlopt(system, x, opt);
}

std::string format_residual(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

const char* backend_name(Backend b) { return b == Backend::Kinsol ? "kinsol" : "nlopt"; }

}  // namespace lpshoot
