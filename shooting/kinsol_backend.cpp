// KINSOL backend: exact Newton (KINSetMaxSetupCalls(1): a fresh Jacobian every iteration) with
// line search and a dense direct solver. Exceptions never cross the C frames: they are stored
// and rethrown after KINSol returns.
#include "nonlinear_solver.hpp"

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <cmath>
#include <exception>
#include <memory>

namespace lpshoot {
namespace {

struct KinsolData {
  NonlinearSystem* system;
  Eigen::VectorXd x, F;
  Eigen::MatrixXd J;
  std::exception_ptr error;
  std::vector<double>* history;
  const SolverOptions* options;
  int jacobians = 0;
};

Eigen::Map<Eigen::VectorXd> view(N_Vector v) {
  return Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer_Serial(v), N_VGetLength_Serial(v));
}

int kin_residual(N_Vector u, N_Vector f, void* user) {
  auto* d = static_cast<KinsolData*>(user);
  try {
    d->x = view(u);
    if (!d->system->residual(d->x, d->F) || !d->F.allFinite()) return 1;  // recoverable: shorter step
    view(f) = d->F;
    return 0;
  } catch (...) {
    d->error = std::current_exception();
    return -1;
  }
}

int kin_jacobian(N_Vector u, N_Vector, SUNMatrix Jm, void* user, N_Vector, N_Vector) {
  auto* d = static_cast<KinsolData*>(user);
  try {
    d->x = view(u);
    if (!d->system->jacobian(d->x, d->J) || !d->J.allFinite()) return 1;
    const sunindextype n = SUNDenseMatrix_Rows(Jm);
    for (sunindextype c = 0; c < n; ++c) {
      sunrealtype* col = SUNDenseMatrix_Column(Jm, c);
      for (sunindextype r = 0; r < n; ++r) col[r] = d->J(r, c);
    }
    // KINSOL evaluates F at u before the Jacobian there: d->F is F(u).
    const double norm = d->F.lpNorm<Eigen::Infinity>();
    if (++d->jacobians > 1) d->history->push_back(norm);  // the start is recorded before KINSol
    if (d->options->on_iteration) d->options->on_iteration(d->jacobians, norm);
    return 0;
  } catch (...) {
    d->error = std::current_exception();
    return -1;
  }
}

// RAII owners of the SUNDIALS objects.
struct Kinsol {
  SUNContext ctx = nullptr;
  N_Vector u = nullptr, scale = nullptr;
  SUNMatrix J = nullptr;
  SUNLinearSolver LS = nullptr;
  void* mem = nullptr;
  Kinsol() = default;
  Kinsol(const Kinsol&) = delete;
  Kinsol& operator=(const Kinsol&) = delete;
  ~Kinsol() {
    if (mem) KINFree(&mem);
    if (LS) SUNLinSolFree(LS);
    if (J) SUNMatDestroy(J);
    if (u) N_VDestroy(u);
    if (scale) N_VDestroy(scale);
    if (ctx) SUNContext_Free(&ctx);
  }
};

}  // namespace

SolverOutcome solve_kinsol(NonlinearSystem& system, Eigen::VectorXd& x, const SolverOptions& opt) {
  SolverOutcome out;
  const int n = system.size();
  KinsolData data{&system, x, Eigen::VectorXd(n), Eigen::MatrixXd(n, n), nullptr, &out.residual_history, &opt};
  Kinsol k;
  if (SUNContext_Create(nullptr, &k.ctx) != 0) throw std::runtime_error("KINSOL: cannot create a context");
  k.u = N_VNew_Serial(n, k.ctx);
  k.scale = N_VNew_Serial(n, k.ctx);
  view(k.u) = x;
  N_VConst(1.0, k.scale);
  k.J = SUNDenseMatrix(n, n, k.ctx);
  k.LS = SUNLinSol_Dense(k.u, k.J, k.ctx);
  k.mem = KINCreate(k.ctx);
  KINInit(k.mem, kin_residual, k.u);
  KINSetUserData(k.mem, &data);
  KINSetLinearSolver(k.mem, k.LS, k.J);
  KINSetJacFn(k.mem, kin_jacobian);
  KINSetMaxSetupCalls(k.mem, 1);  // exact Newton: fresh Jacobian each iteration
  KINSetFuncNormTol(k.mem, opt.tolerance);
  KINSetScaledStepTol(k.mem, 1e-15);
  KINSetNumMaxIters(k.mem, opt.max_iterations);
  KINSetMaxNewtonStep(k.mem, 1e12);  // unknowns start at 0: the default (1000 x |u0|) is meaningless here
  KINSetPrintLevel(k.mem, 0);
  KINSetErrHandlerFn(k.mem, [](int, const char*, const char*, char*, void*) {}, nullptr);  // library never prints

  // Record the residual at the start.
  if (system.residual(x, data.F)) out.residual_history.push_back(data.F.lpNorm<Eigen::Infinity>());
  const int flag = KINSol(k.mem, k.u, KIN_LINESEARCH, k.scale, k.scale);
  if (data.error) std::rethrow_exception(data.error);
  long iters = 0;
  KINGetNumNonlinSolvIters(k.mem, &iters);
  out.iterations = static_cast<int>(iters);
  x = view(k.u);
  const bool ok = system.residual(x, data.F);
  out.residual_norm = ok ? data.F.lpNorm<Eigen::Infinity>() : INFINITY;
  out.residual_history.push_back(out.residual_norm);
  char* name = KINGetReturnFlagName(flag);
  const std::string flag_name = name ? name : "unknown";
  free(name);
  if (ok && out.residual_norm <= opt.tolerance) {
    out.status = SolverStatus::Converged;
  } else {
    out.status = flag < 0 ? SolverStatus::Failed : SolverStatus::NotConverged;
    out.message = "KINSOL stopped with " + flag_name + " after " + std::to_string(out.iterations) +
                  " iterations, residual " + format_residual(out.residual_norm);
  }
  return out;
}

}  // namespace lpshoot
