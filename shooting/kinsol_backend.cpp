// KINSOL backend: exact Newton (KINSetMaxSetupCalls(1): a fresh Jacobian every iteration; for an
// affine F, SolverOptions::affine, one Jacobian for the full steps, whose Newton steps it gives) with
// SUNDIALS' band LU when the system's pattern is banded (BandLU::pays: the shooting Jacobian,
// block bidiagonal; no ordering step, partial pivoting within the band), else KLU, its sparse
// direct solver (compressed sparse columns; fill-reducing ordering, partial pivoting), in two
// phases:
//  1. full Newton steps (KIN_NONE). The Newton step does not depend on how rows are scaled, but a
//     line search's merit ½|F|² does, and shooting rows are scaled by their tolerances (spread
//     1e4): a step that cuts the max-norm 30-fold can raise that merit 20-fold (rows exactly
//     satisfied at the guess, now slightly violated, weigh 1e4 times more), so the line search
//     crawls (beanie, 50 segments: 19 iterations against 3 for full steps).
//     An iterate that will not converge (jacobian_expected) is evaluated with its Jacobian in
//     the same sweep (NonlinearSystem::expect_jacobian), which KINSOL then asks for. An iterate
//     from which a chord step (the last Jacobian again) is expected to converge
//     (chord_converges) is evaluated without, and takes that step: exact Newton's last
//     Jacobian costs a sweep with sensitivities (a Galerkin beanie's: ~6x one without).
//  2. if full steps diverge (the unscaled residual, NonlinearSystem::progress_norm, above 10x
//     the start's, or F not evaluable) or do not converge: KIN_LINESEARCH from the best iterate
//     (stopped when it crawls, if SolverOptions::stop_when_crawling asks).
// Exceptions never cross the C frames: they are stored and rethrown after KINSol returns.
#include "band_lu.hpp"
#include "huge_pages.hpp"
#include "nonlinear_solver.hpp"

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_band.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_band.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <exception>
#include <memory>
#include <type_traits>

namespace lpshoot {
namespace {

struct KinsolData {
  NonlinearSystem* system = nullptr;
  Eigen::VectorXd x, F;
  SparseJacobian J;
  SUNLinearSolver LS = nullptr;  // to reset KLU's symbolic analysis when the pattern changes
  bool band = false;             // SUNDIALS' band matrix and LU instead of KLU
  std::exception_ptr error;
  std::vector<double>* history = nullptr;
  const SolverOptions* options = nullptr;
  int jacobians = 0;
  // Phase 1 (full steps): stop when the residual exceeds `abort_above` or cannot be evaluated.
  bool full_steps = false, aborted = false, stalled = false;
  double abort_above = INFINITY;
  double best_progress = INFINITY;  // lowest progress norm of phase 1, and evaluations since it halved
  int since_halved = 0;
  double best_norm = INFINITY;  // lowest max-norm seen, and where
  Eigen::VectorXd best_x;
  double start_norm = INFINITY;  // max-norm at the start
  // An affine F's full steps evaluate no Jacobian after the first: each iterate's residual norm
  // is recorded when the next iterate is evaluated (as a Jacobian there would record it).
  bool record_at_residuals = false;
  int residuals = 0;  // evaluations in this KINSOL run
  double pending = NAN;
  // The last two residual norms, to predict whether a full step's next iterate converges.
  double norm_last = INFINITY, norm_before = INFINITY;
  // A chord step (the last Jacobian again, no sweep with sensitivities) is planned at the iterate
  // being evaluated (chord_planned), and J holds a Jacobian evaluated at the previous iterate
  // (fresh_jacobian: not itself reused).
  bool chord_planned = false, fresh_jacobian = false;
  bool chord_taken = false;  // the last step was a chord step
  // Phase 2: where its iterates start in the history, and whether it was stopped for crawling.
  size_t search_start = 0;
  bool crawled = false;
};

// The line search crawls: over its last `crawl_window` iterations the residual's max-norm fell
// less than `crawl_cut`-fold (SolverOptions::stop_when_crawling). Both figures come from one
// problem (the spherical pendulum's windows, bench/RESULTS.md); they are not tuned on others.
constexpr int crawl_window = 5;
constexpr int crawl_cut = 2;
bool crawling(const KinsolData& d) {
  const std::vector<double>& h = *d.history;
  const size_t n = h.size();
  return !d.full_steps && d.options->stop_when_crawling && n >= d.search_start + crawl_window + 1 &&
         !(crawl_cut * h[n - 1] <= h[n - 1 - crawl_window]);
}

// Whether a full Newton step's next iterate will need the Jacobian: its residual, predicted
// from quadratic convergence (e_next = C e², C from the last two norms: e_last³ / e_before²),
// stays above 10x the tolerance. An iterate predicted to converge gets a residual-only
// evaluation, so a wrong guess either way costs what it cost before (or one sweep).
bool jacobian_expected(const KinsolData& d) {
  if (!d.full_steps || d.record_at_residuals) return false;  // line search, or an affine F's steps
  const double tol = d.options->tolerance;
  if (!(d.norm_before < INFINITY) || !(d.norm_before > 0)) return d.norm_last > 10 * tol;
  const double ratio = d.norm_last / d.norm_before;
  return d.norm_last * ratio * ratio > 10 * tol;
}

// Whether a chord step from an iterate with residual norm e (the Jacobian of the iterate before,
// whose norm was e_before) is expected to converge: the chord contracts by ~|J_before - J| |J^-1|,
// of the order of the last step's contraction e / e_before under quadratic convergence, so it
// lands near e² / e_before. It replaces a sweep with sensitivities by one without (beanie
// Galerkin 6 at N = 16: ~0.85 against ~0.15 ms); a wrong guess costs one sweep without.
bool chord_converges(double e, double e_before, double tol) {
  return e_before > 0 && e_before < INFINITY && e * (e / e_before) <= tol;
}

// Before an iterate is evaluated: plan a chord step there when its predicted norm (quadratic
// convergence, as jacobian_expected) would leave a chord step converged with a margin of 10. The
// prediction can be several times low early on (beanie Galerkin 4, N = 160: 8.2e3 predicted,
// 3.8e4 found, in units of the tolerance); an unconfirmed plan costs a sweep without
// sensitivities, then the sweep with them anyway.
bool chord_expected(const KinsolData& d) {
  if (!d.full_steps || d.record_at_residuals || !d.fresh_jacobian) return false;
  if (!(d.norm_before < INFINITY) || !(d.norm_before > 0)) return false;
  const double ratio = d.norm_last / d.norm_before, predicted = d.norm_last * ratio * ratio;
  return chord_converges(predicted, d.norm_last, 0.1 * d.options->tolerance);
}

// Full steps that cut the residual at least a thousandfold and reached 100x the tolerance are
// at the noise of F (shooting: the flows' rounding) once they stop halving.
bool at_noise(const KinsolData& d) {
  return d.best_norm <= 100 * d.options->tolerance && d.start_norm >= 1e3 * d.best_norm;
}

// At the noise and still 2x above the tolerance, a further evaluation (a noise sample, ~10%
// apart) will not land below it: two evaluations that do not halve the residual end the full
// steps instead of four (the beanie on Galerkin 4, N = 10^5 at tolerance 2e-11: the noise at
// 1.4-1.6x the row tolerance, each stalled iteration two sweeps, ~8 s of one thread; N = 10^6
// at 1e-10: ~3x). Within 2x, four tries as elsewhere (the paper's scheme at its floor, N = 10^4:
// samples around 1.15x, some below 1).
bool noise_above_tolerance(const KinsolData& d) { return at_noise(d) && d.best_norm >= 2 * d.options->tolerance; }

// How many evaluations that do not halve the residual end the full steps: four, two at the noise
// above twice the tolerance (above), and one there after an exact Newton step (the Jacobian
// evaluated at the iterate before, not a chord step): within 100x the tolerance of a residual
// already cut a thousandfold, an exact step converges quadratically unless the residual is
// noise, so one that does not halve it has sampled the noise. A chord step contracts only
// linearly and keeps the two. Each further sample is two sweeps (the Jacobian at the last iterate,
// then the residual at the next): the beanie on Galerkin 4 at N = 10^6, tolerance 1e-10, from a
// coarser grid's solution (5.9e4 -> 3.14 -> 3.05 -> 3.05 x tolerance), ~20 s of one thread.
int stall_evaluations(const KinsolData& d) {
  if (!noise_above_tolerance(d)) return 4;
  return d.fresh_jacobian ? 1 : 2;
}

Eigen::Map<Eigen::VectorXd> view(N_Vector v) {
  return Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer_Serial(v), N_VGetLength_Serial(v));
}

int kin_residual(N_Vector u, N_Vector f, void* user) {
  auto* d = static_cast<KinsolData*>(user);
  try {
    d->x = view(u);
    d->chord_planned = chord_expected(*d);
    d->system->expect_jacobian(!d->chord_planned && jacobian_expected(*d));
    const bool ok = d->system->residual(d->x, d->F) && d->F.allFinite();
    d->system->expect_jacobian(false);
    const double norm = ok ? d->F.lpNorm<Eigen::Infinity>() : INFINITY;
    d->norm_before = d->norm_last;
    d->norm_last = norm;
    // The best iterate first: a stall declared here returns this one when it is the best, whose
    // runs the system still holds (no sweep to propagate the one before again).
    if (norm < d->best_norm) {
      d->best_norm = norm;
      d->best_x = d->x;
    }
    if (d->full_steps) {
      const double progress = ok ? d->system->progress_norm(d->F) : INFINITY;
      if (!(progress <= d->abort_above)) {
        d->aborted = true;
        return -1;  // unrecoverable: phase 1 ends, the line search takes over
      }
      if (progress <= 0.5 * d->best_progress || d->best_progress == INFINITY) {
        d->best_progress = progress;
        d->since_halved = 0;
      } else if (++d->since_halved >= stall_evaluations(*d)) {  // no longer converging
        d->stalled = true;
        return -1;
      }
    }
    if (!ok) return 1;  // recoverable: the line search shortens the step
    if (d->record_at_residuals && d->residuals++ > 0) {  // the first is F at the start, recorded before
      if (!std::isnan(d->pending)) {
        d->history->push_back(d->pending);
        if (d->options->on_iteration) d->options->on_iteration(++d->jacobians, d->pending);
      }
      d->pending = norm;
    }
    view(f) = d->F;
    return 0;
  } catch (...) {
    d->error = std::current_exception();
    return -1;
  }
}

// Copies J (compressed) into the SUNDIALS CSC matrix (reallocated when it grows) and makes KLU
// factor it afresh: SUNDIALS would otherwise refactor on the previous pivot order, which keeps
// the old pivots whatever their growth (40x the error of a fresh factorization on a beanie
// Newton step, tests/test_structured.cpp). Ordering a block-bidiagonal pattern costs O(nnz).
void copy_to_sundials(const SparseJacobian& J, SUNMatrix Jm, SUNLinearSolver LS) {
  const sunindextype n = SUNSparseMatrix_Columns(Jm), nnz = J.nonZeros();
  sunindextype* colptr = SUNSparseMatrix_IndexPointers(Jm);
  bool same = SUNSparseMatrix_NNZ(Jm) >= nnz && colptr[n] == nnz;
  for (sunindextype c = 0; same && c <= n; ++c) same = colptr[c] == J.outerIndexPtr()[c];
  for (sunindextype i = 0; same && i < nnz; ++i) same = SUNSparseMatrix_IndexValues(Jm)[i] == J.innerIndexPtr()[i];
  if (!same) {
    if (SUNSparseMatrix_NNZ(Jm) < nnz && SUNSparseMatrix_Reallocate(Jm, nnz) != 0)
      throw std::runtime_error("KINSOL: cannot allocate the sparse Jacobian");
    colptr = SUNSparseMatrix_IndexPointers(Jm);
    for (sunindextype c = 0; c <= n; ++c) colptr[c] = J.outerIndexPtr()[c];
    for (sunindextype i = 0; i < nnz; ++i) SUNSparseMatrix_IndexValues(Jm)[i] = J.innerIndexPtr()[i];
  }
  SUNLinSol_KLUReInit(LS, Jm, SUNSparseMatrix_NNZ(Jm), SUNKLU_REINIT_PARTIAL);
  std::copy(J.valuePtr(), J.valuePtr() + nnz, SUNSparseMatrix_Data(Jm));
}

// The same into a SUNDIALS band matrix (its bandwidths are the pattern's, fixed for the solve).
void copy_to_band(const SparseJacobian& J, SUNMatrix Jm) {
  const sunindextype ml = SUNBandMatrix_LowerBandwidth(Jm), mu = SUNBandMatrix_UpperBandwidth(Jm);
  SUNMatZero(Jm);
  for (int c = 0; c < J.outerSize(); ++c) {
    sunrealtype* column = SUNBandMatrix_Column(Jm, c);  // at the diagonal
    for (SparseJacobian::InnerIterator it(J, c); it; ++it) {
      const sunindextype offset = it.row() - c;
      if (offset > ml || -offset > mu) throw std::runtime_error("KINSOL: the Jacobian left the band it was set up with");
      column[offset] = it.value();
    }
  }
}

int kin_jacobian(N_Vector u, N_Vector, SUNMatrix Jm, void* user, N_Vector, N_Vector) {
  auto* d = static_cast<KinsolData*>(user);
  try {
    d->x = view(u);
    // The planned chord step, if the residual here confirms it (else a fresh Jacobian).
    const bool chord = d->chord_planned && d->fresh_jacobian &&
                       chord_converges(d->norm_last, d->norm_before, d->options->tolerance);
    d->chord_planned = false;
    if (!chord) {
      if (!d->system->jacobian(d->x, d->J)) return 1;
      d->J.makeCompressed();
      if (!Eigen::Map<const Eigen::VectorXd>(d->J.valuePtr(), d->J.nonZeros()).allFinite()) return 1;
    }
    d->fresh_jacobian = !chord;
    d->chord_taken = chord;
    if (d->band)
      copy_to_band(d->J, Jm);
    else
      copy_to_sundials(d->J, Jm, d->LS);
    // KINSOL evaluates F at u before the Jacobian there: d->F is F(u).
    const double norm = d->F.lpNorm<Eigen::Infinity>();
    if (d->record_at_residuals && d->jacobians > 0) return 0;  // recorded at the residuals (a refresh)
    if (++d->jacobians > 1) d->history->push_back(norm);  // the start is recorded before KINSol
    if (d->options->on_iteration) d->options->on_iteration(d->jacobians, norm);
    if (crawling(*d)) {
      d->crawled = true;
      return -1;  // unrecoverable: KINSOL stops, the caller tries its remedy
    }
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

// After a converged run that ended with a chord step, one more chord correction with the same
// factorization (still in KLU): the chord leaves ~|J_before - J| |J^-1| |e|, up to the tolerance,
// where exact Newton's last step leaves ~|e|²; the correction brings it there (boundary data such
// as the beanie's θ(T) to 1e-12 at tolerance 1e-10, tests/test_galerkin.cpp). One sweep without
// sensitivities; kept if the residual does not grow or stays within the tolerance. At the noise
// the two residuals are samples of it, and a polished iterate dropped for the one before costs a
// sweep to propagate that one's trajectory again (the beanie on Galerkin 4 at N = 10^5, both
// within the tolerance: one sweep more, seven instead of six).
void polish_after_chord(KinsolData& d, Kinsol& k) {
  Eigen::VectorXd F, F1;
  d.system->expect_jacobian(false);
  const Eigen::VectorXd x = view(k.u);
  if (!d.system->residual(x, F) || !F.allFinite()) return;  // the last evaluation's point: no sweep
  const std::unique_ptr<std::remove_pointer_t<N_Vector>, void (*)(N_Vector)> b(N_VClone(k.u), N_VDestroy),
      dx(N_VClone(k.u), N_VDestroy);
  if (!b || !dx) return;
  view(b.get()) = -F;
  if (SUNLinSolSolve(k.LS, k.J, dx.get(), b.get(), 0.0) != 0) return;
  const Eigen::VectorXd x1 = x + view(dx.get());
  if (x1.allFinite() && d.system->residual(x1, F1) && F1.allFinite() &&
      F1.lpNorm<Eigen::Infinity>() <= std::max(F.lpNorm<Eigen::Infinity>(), d.options->tolerance))
    view(k.u) = x1;
}

// One KINSOL run from x with the given strategy; returns KINSOL's flag and adds its iterations.
int kinsol_run(KinsolData& data, Eigen::VectorXd& x, const SolverOptions& opt, int strategy, int& iterations) {
  const int n = static_cast<int>(x.size());
  Kinsol k;
  if (SUNContext_Create(nullptr, &k.ctx) != 0) throw std::runtime_error("KINSOL: cannot create a context");
  k.u = N_VNew_Serial(n, k.ctx);
  k.scale = N_VNew_Serial(n, k.ctx);
  view(k.u) = x;
  N_VConst(1.0, k.scale);
  const NonlinearSystem::Pattern pattern = data.system->pattern();
  data.band = opt.linear_solver == LinearSolver::Band ||
              (opt.linear_solver == LinearSolver::Auto && BandLU::pays(n, pattern.kl, pattern.ku, pattern.nonzeros));
  if (data.band) {
    if (pattern.kl < 0) throw std::invalid_argument("the band linear solver needs the Jacobian's bandwidths");
    k.J = SUNBandMatrix(n, std::min(pattern.ku, n - 1), std::min(pattern.kl, n - 1), k.ctx);
    if (k.J) advise_huge_pages(SUNBandMatrix_Data(k.J), static_cast<std::size_t>(SUNBandMatrix_LDim(k.J) * SUNBandMatrix_Columns(k.J)) * sizeof(sunrealtype));
    k.LS = k.J ? SUNLinSol_Band(k.u, k.J, k.ctx) : nullptr;
    if (!k.J || !k.LS) throw std::runtime_error("KINSOL: cannot create the band linear solver");
  } else {
    // An empty pattern: the first Jacobian sets it (copy_to_sundials).
    k.J = SUNSparseMatrix(n, n, std::max(1, n), CSC_MAT, k.ctx);
    if (k.J) std::fill(SUNSparseMatrix_IndexPointers(k.J), SUNSparseMatrix_IndexPointers(k.J) + n + 1, sunindextype(0));
    k.LS = k.J ? SUNLinSol_KLU(k.u, k.J, k.ctx) : nullptr;
    if (!k.J || !k.LS) throw std::runtime_error("KINSOL: cannot create the sparse linear solver");
    SUNLinSol_KLUGetCommon(k.LS)->tol = 1.0;  // strict partial pivoting (KLU's default 0.001 prefers the diagonal)
  }
  data.LS = k.LS;
  k.mem = KINCreate(k.ctx);
  KINInit(k.mem, kin_residual, k.u);
  KINSetUserData(k.mem, &data);
  KINSetLinearSolver(k.mem, k.LS, k.J);
  KINSetJacFn(k.mem, kin_jacobian);
  // Exact Newton: a fresh Jacobian each iteration, or for an affine F's full steps the first one
  // throughout (KINSOL still refreshes it if a linear solve fails).
  const bool affine_steps = opt.affine && strategy == KIN_NONE;
  KINSetMaxSetupCalls(k.mem, affine_steps ? opt.max_iterations + 1 : 1);
  data.record_at_residuals = affine_steps;
  data.residuals = 0;
  data.pending = NAN;
  KINSetFuncNormTol(k.mem, opt.tolerance);
  KINSetScaledStepTol(k.mem, 1e-15);
  KINSetNumMaxIters(k.mem, std::max(1, opt.max_iterations - iterations));
  KINSetMaxNewtonStep(k.mem, 1e12);  // unknowns start at 0: the default (1000 x |u0|) is meaningless here
  KINSetPrintLevel(k.mem, 0);
  KINSetErrHandlerFn(k.mem, [](int, const char*, const char*, char*, void*) {}, nullptr);  // library never prints
  data.chord_taken = false;
  const int flag = KINSol(k.mem, k.u, strategy, k.scale, k.scale);
  if (data.error) std::rethrow_exception(data.error);
  if (flag >= 0 && data.chord_taken) polish_after_chord(data, k);
  long iters = 0;
  KINGetNumNonlinSolvIters(k.mem, &iters);
  iterations += static_cast<int>(iters);
  x = view(k.u);
  return flag;
}

std::string flag_name(int flag) {
  char* name = KINGetReturnFlagName(flag);
  const std::string s = name ? name : "unknown";
  free(name);
  return s;
}

}  // namespace

SolverOutcome solve_kinsol(NonlinearSystem& system, Eigen::VectorXd& x, const SolverOptions& opt) {
  SolverOutcome out;
  KinsolData data;
  data.system = &system;
  data.history = &out.residual_history;
  data.options = &opt;

  // Record the residual at the start.
  if (!system.residual(x, data.F) || !data.F.allFinite()) {
    out.status = SolverStatus::Failed;
    out.message = "the residual cannot be evaluated at the initial guess";
    out.residual_norm = INFINITY;
    return out;
  }
  const double start = data.F.lpNorm<Eigen::Infinity>();
  data.norm_last = start;
  out.residual_history.push_back(start);
  data.best_norm = start;
  data.best_x = x;
  data.start_norm = start;

  auto converged = [&](const Eigen::VectorXd& at) {
    return system.residual(at, data.F) && data.F.allFinite() && data.F.lpNorm<Eigen::Infinity>() <= opt.tolerance;
  };
  // Phase 1: full Newton steps.
  data.full_steps = true;
  data.abort_above = 10 * system.progress_norm(data.F);
  Eigen::VectorXd x1 = x;
  int flag = kinsol_run(data, x1, opt, KIN_NONE, out.iterations);
  std::string phases;
  if (!data.aborted && !data.stalled && converged(x1)) {
    x = x1;
  } else if (data.stalled && data.best_norm <= opt.tolerance && converged(data.best_x)) {
    x = data.best_x;
  } else if (data.stalled && at_noise(data)) {
    // Full steps cut the residual at least a thousandfold, then stopped halving within 100x the
    // tolerance: that is the noise of F (shooting: the flows' rounding), which a line search
    // cannot go below; it would only spend evaluations (a sweep of the beanie at N = 10^6 takes
    // ~85 s). The caller names the floor.
    x = data.best_x;
    out.stalled_at_noise = true;
    phases = " (full Newton steps stalled after " + std::to_string(out.iterations) +
             " iterations within 100x the tolerance, at the noise of the residual; no line search)";
  } else {
    // Phase 2: line search from the best iterate so far.
    const std::string what = data.aborted ? "diverged after " : data.stalled ? "stalled after " : "did not converge in ";
    phases = " (full Newton steps " + what + std::to_string(out.iterations) + " iterations";
    data.full_steps = false;
    x = data.best_x;
    if (out.iterations < opt.max_iterations) {
      phases += "; then line search";
      data.search_start = out.residual_history.size();
      flag = kinsol_run(data, x, opt, KIN_LINESEARCH, out.iterations);
      if (data.crawled)
        phases += ", stopped when it crawled (the residual fell less than " + std::to_string(crawl_cut) +
                  "-fold in " + std::to_string(crawl_window) + " iterations)";
    }
    phases += ")";
    if (data.best_norm < INFINITY && !converged(x)) x = data.best_x;  // never return worse than seen
  }
  const bool ok = system.residual(x, data.F) && data.F.allFinite();
  out.residual_norm = ok ? data.F.lpNorm<Eigen::Infinity>() : INFINITY;
  out.residual_history.push_back(out.residual_norm);
  if (ok && out.residual_norm <= opt.tolerance) {
    out.status = SolverStatus::Converged;
  } else {
    out.status = flag < 0 && !data.crawled ? SolverStatus::Failed : SolverStatus::NotConverged;
    const std::string why = data.crawled ? std::string("its line search crawling") : flag_name(flag);
    out.message = "KINSOL stopped with " + why + " after " + std::to_string(out.iterations) + " iterations" +
                  phases + ", residual " + format_residual(out.residual_norm);
  }
  return out;
}

}  // namespace lpshoot
