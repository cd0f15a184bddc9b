// Single and multiple shooting for discrete boundary value problems (METHOD.md §5), for the
// paper's nodal windows (BoundaryValueProblem<P>, ShootingGuess<P>) and for the Galerkin schemes
// (GalerkinBVP<Sch>, GalerkinGuess<Sch>): the same driver over the scheme adapters of
// shooting_system.hpp. solve_bvp returns a ShootingResult: status and message (why it did not
// converge, or which conditions are dependent), the trajectory, cost, diagnostics.
#pragma once

#include "diagnostics.hpp"
#include "shooting_system.hpp"

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>

namespace lpshoot {

enum class ShootingMethod { Single, Multiple };

// Multiple shooting: where segments 1, 2, ... start. Guess: the guess's states there. Propagated:
// the end of the previous segment run from its start (a forward sweep from the guess's initial
// state): the continuity defects vanish and the first Newton step is single shooting's. Auto:
// from the guess, and when that does not converge, again from the sweep (the sweep wins when the
// guess's interior states are far from the dynamics, e.g. a stiff potential; the guess when the
// flow is unstable or the guess is a near solution, e.g. a resampled one).
enum class SegmentStarts { Guess, Propagated, Auto };

// Multiple shooting's segment count for "auto" (the application's default too): segments of at
// most 100 steps. A nodal recursion amplifies its rounding like L^4 eps over L steps (METHOD.md
// §5): 100 steps keep that near 1e-8 of the state's size; unstable flows stay bounded over a
// segment; the structured linear algebra makes the count's cost linear.
inline int auto_segments(int steps) { return std::max(1, steps / 100 + (steps % 100 != 0)); }

// How many times "auto" doubles the segments when Newton does not converge
// (ShootingOptions::segment_doublings): 1, 2 and 4 times the auto count are tried.
constexpr int auto_segment_doublings = 2;

struct ShootingOptions {
  ShootingMethod method = ShootingMethod::Single;
  int segments = 0;  // multiple shooting; 0: auto_segments(N)
  SegmentStarts segment_starts = SegmentStarts::Auto;
  SolverOptions solver;
  NewtonOptions step;
  double rank_tolerance = 1e-10;  // singular values of the equilibrated Jacobian below this times the largest count as zero
  int threads = 0;               // 0: one per available core
  // When a solve does not converge for a reason more segments address (Newton did not bring the
  // residual down from the guess, or the flow failed from it), solve again with twice the
  // segments, at most this many times. -1: auto_segment_doublings when segments is auto (0),
  // none for a given count.
  int segment_doublings = -1;
  // Called as segments are propagated within one evaluation (segment done, of S): progress for
  // evaluations that take long (large N); may throw to stop the solve.
  std::function<void(int, int)> on_segment;
  // Galerkin schemes: a solve on N >= coarse_start_from steps (and not affine) starts from the
  // solution on N / coarse_ratio steps (coarse_start.hpp); 0: from the guess, whatever N.
  int coarse_start_from = 20000;
  int coarse_ratio = 100;
};

enum class ShootingStatus { Converged, NotConverged, RankDeficient, FlowFailed, InvalidProblem };

// X: the discrete problem P (the paper's windows) or a Galerkin<C, S, Q>.
template <class X>
struct ShootingResult {
  using A = SchemeFor<X>;
  ShootingStatus status = ShootingStatus::NotConverged;
  std::string message;  // one sentence: what failed, why, and the one thing to try
  std::string detail;   // the solver's own account (flags, phases), the other attempt's outcome
  int iterations = 0;
  std::vector<double> residual_history;
  // NaN below: not evaluated (a flow that failed from the guess leaves no residual, Jacobian or
  // trajectory; 0 would read as a perfect solve). Infinity: evaluated and overflowed.
  double residual_norm = std::numeric_limits<double>::quiet_NaN();
  // 1-norm condition estimate of the equilibrated shooting Jacobian at the solution
  double condition = std::numeric_limits<double>::quiet_NaN();
  double raw_residual_norm = std::numeric_limits<double>::quiet_NaN();  // max-norm of the conditions in their own units
  // residual_norm: max over rows of |F_i| / tolerance_i (<= 1 at convergence); tolerance_i is the
  // solver tolerance plus the row's roundoff floor (see row_tolerances).
  int rank = -1, unknowns = 0;  // rank -1: not computed (the flow failed or overflowed there)
  std::vector<std::string> dependent_conditions;  // when rank deficient
  std::vector<double> singular_values;            // of the equilibrated Jacobian, when rank deficient
  double wall_time_s = 0;
  typename A::Trajectory trajectory;
  std::vector<typename A::GroupElem> g;    // g_0 .. g_N
  double cost = std::numeric_limits<double>::quiet_NaN();  // the discrete cost (Σ L_d without multiplier terms)
  double momentum_drift = 0;               // relative max |J_n - J_first| of the discrete momentum map
  bool propagated_starts = false;          // multiple shooting started from the forward sweep
  bool stalled_at_floor = false;           // not converged: stalled at the flows' roundoff floor
  int segments = 0;                        // the segment count of this attempt (1: single shooting)
  std::vector<int> failed_segment_counts;  // earlier attempts with fewer segments (segment_doublings)
  // A start from coarser grids (ShootingOptions::coarse_start_from): their N, coarsest first
  // (empty: solved from the guess), and the Newton iterations spent on them.
  std::vector<int> coarse_grids;
  int coarse_iterations = 0;
  bool ok() const { return status == ShootingStatus::Converged; }
};

const char* status_name(ShootingStatus s);

namespace detail {

// Segment starts by a forward sweep: segment i+1 begins where segment i, run from its start,
// ends (stops at the first segment whose flow fails, keeping the given starts from there on).
template <class X>
std::vector<typename SchemeFor<X>::State> forward_sweep(const typename SchemeFor<X>::BVP& bvp,
                                                        std::vector<typename SchemeFor<X>::State> refs,
                                                        const std::vector<int>& starts, const NewtonOptions& step) {
  using A = SchemeFor<X>;
  const auto flow = A::flow(bvp, step);
  for (size_t i = 0; i + 1 < refs.size(); ++i) {
    const auto run = A::run(flow, refs[i], starts[i], starts[i + 1] - starts[i], nullptr);
    if (!run.report.ok()) break;
    refs[i + 1] = A::end_state(run);
  }
  return refs;
}

// One shooting solve from the given segment start states (the unknowns start at 0).
template <class X>
ShootingResult<X> solve_from_starts(const typename SchemeFor<X>::BVP& bvp,
                                    const std::vector<typename SchemeFor<X>::State>& refs,
                                    const std::vector<int>& starts, const ShootingOptions& opt) {
  using A = SchemeFor<X>;
  const int S = static_cast<int>(refs.size());
  const auto t0 = std::chrono::steady_clock::now();
  ShootingResult<X> out;
  auto finish = [&](ShootingStatus st, std::string msg) {
    out.status = st;
    out.message = std::move(msg);
    out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::move(out);  // every call is the function's return: no copy of the trajectory
  };
  ShootingSystem<X> system(bvp, refs, starts, opt.step, opt.threads);
  system.set_on_segment(opt.on_segment);
  out.unknowns = system.size();

  Eigen::VectorXd x = Eigen::VectorXd::Zero(system.size());
  {  // The guess must be evaluable. With its Jacobian: the row tolerances and the solver's first
     // iteration use this evaluation (kept by the system), no other is made at the guess.
    SparseJacobian J0;
    if (!system.jacobian(x, J0))
      return finish(ShootingStatus::FlowFailed, "the discrete flow failed from the initial guess: " + system.last_failure());
  }
  // Rows scaled by 1/(their tolerance): the solver then stops at a max-norm of 1.
  system.set_row_scaling(system.row_tolerances(x, opt.solver.tolerance).cwiseInverse());
  SolverOptions scaled = opt.solver;
  scaled.tolerance = 1.0;
  scaled.affine = A::affine(bvp, opt.step);
  const SolverOutcome so = solve_nonlinear(system, x, scaled);
  out.iterations = so.iterations;
  out.residual_history = so.residual_history;
  out.residual_norm = so.residual_norm;

  // The trajectory at the final iterate (from the solver's last evaluation, which was there).
  std::vector<typename A::Run> runs;
  std::vector<typename A::State> st;
  if (!system.runs_at(x, runs, st))
    return finish(ShootingStatus::FlowFailed, "the discrete flow failed at the final iterate: " + system.last_failure());
  A::assemble(bvp, runs, st[0], out);
  {
    Eigen::VectorXd F;
    out.raw_residual_norm = system.raw_residual(x, F) ? F.lpNorm<Eigen::Infinity>() : INFINITY;
  }

  // Conditioning and rank of the shooting Jacobian (structured: sparse QR and LU). At a converged
  // solution, the last Newton iteration's Jacobian, one step away, serves: its rank and condition
  // are the solution's; so it does after a stall at the flows' noise, whose iterates differ by
  // that noise; otherwise the Jacobian at the final iterate (a sweep with sensitivities).
  SparseJacobian J;
  const bool near = so.status == SolverStatus::Converged || so.stalled_at_noise;
  const bool have_J = near && system.last_jacobian().rows() == system.size()
                          ? (J = system.last_jacobian(), true)
                          : system.jacobian(x, J);
  if (have_J) {
    RankDiagnosis diag = diagnose_rank(std::move(J), system.row_names(), opt.rank_tolerance);
    out.rank = diag.rank;
    out.condition = diag.condition;
    out.dependent_conditions = std::move(diag.dependent_conditions);
    out.singular_values = std::move(diag.singular_values);
  }
  // The backend's account ("KINSOL stopped with ... , residual 24.2"): residuals of scaled rows.
  const bool names_residual = so.message.find(", residual ") != std::string::npos;
  out.detail = so.message.empty() ? std::string() : so.message + (names_residual ? " x tolerance" : "");
  // A solver that ran away from the guess leaves a Jacobian whose rank says nothing about the data.
  const bool diverged = so.status != SolverStatus::Converged && !so.residual_history.empty() &&
                        !(out.residual_norm <= so.residual_history.front());
  // Nor does one where the flow has blown up (conditions off by more than 1e3 in their own units,
  // e.g. a stiff potential from a poor guess): that is a failure to converge, whatever the rank.
  const bool far = so.status != SolverStatus::Converged && !(out.raw_residual_norm <= 1e3);
  const std::string rank_note = out.rank >= 0 && out.rank < out.unknowns && !far ? " (the Jacobian there has rank " + std::to_string(out.rank) +
                                                              " of " + std::to_string(out.unknowns) + ")"
                                                        : std::string();
  // A tolerance below the scheme's roundoff floor on this grid (row_tolerances): a Jacobian that
  // looks rank deficient there is the ill-conditioning of the states, not dependent data. Only
  // where the residual came down near that floor: a Newton that stopped far above it (the
  // spherical pendulum's paper windows on one segment of 80 steps at 1e-11: 5.8e8 x tolerance
  // against a floor of 1.6e4) failed for another reason.
  const bool below_floor = so.status != SolverStatus::Converged && !diverged && !far && system.floor_ratio() > 1e4 &&
                           out.residual_norm <= 1e3 * system.floor_ratio();
  if (out.rank >= 0 && out.rank < out.unknowns && !diverged && !far && !below_floor) {
    std::string msg = "the shooting Jacobian is rank deficient (rank " + std::to_string(out.rank) + " of " +
                      std::to_string(out.unknowns) +
                      "): redundant or inconsistent boundary data, or a discrete problem that is (nearly) singular at "
                      "this step size; dependent: ";
    for (size_t i = 0; i < out.dependent_conditions.size() && i < 3; ++i) msg += (i ? "; " : "") + out.dependent_conditions[i];
    if (out.dependent_conditions.size() > 3)
      msg += "; and " + std::to_string(out.dependent_conditions.size() - 3) + " more";
    return finish(ShootingStatus::RankDeficient, msg);
  }
  if (so.status != SolverStatus::Converged) {
    std::string msg;
    if (so.residual_history.empty()) {
      msg = "the shooting residual is not finite at the guess (the flow overflows from it): try multiple shooting with "
            "more segments, a smaller h, or a better guess";
    } else if (!std::isfinite(out.residual_norm)) {
      msg = "the shooting residual is not finite at the solver's last iterate (the flow overflows there), from " +
            format_residual(so.residual_history.front()) +
            " x tolerance at the guess: try multiple shooting with more segments, a smaller h, or a better guess";
    } else if (diverged) {
      msg = "the residual grew from " + format_residual(so.residual_history.front()) + " at the guess to " +
            format_residual(out.residual_norm) + " x tolerance" + rank_note +
            ": try multiple shooting with more segments, a smaller h, or a better guess";
    } else if (below_floor) {
      out.stalled_at_floor = true;
      msg = "the residual stalled at " + format_residual(out.residual_norm) + " x tolerance" + rank_note +
            ": the tolerance is below the roundoff floor of this scheme at h = " + format_residual(bvp.h()) +
            " (estimated at " + format_residual(system.floor_ratio()) + " x tolerance on the worst row); " +
            A::floor_remedy;
    } else if (out.residual_norm < 1e3 && so.residual_history.front() > 1e3 * out.residual_norm) {
      out.stalled_at_floor = true;
      int longest = 0;
      for (int i = 0; i < S; ++i) longest = std::max(longest, starts[i + 1] - starts[i]);
      msg = "the residual stalled at " + format_residual(out.residual_norm) + " x tolerance after a " +
            format_residual(so.residual_history.front() / out.residual_norm) +
            "-fold reduction, the roundoff floor of the flow on this grid (h = " + format_residual(bvp.h()) + ", " +
            std::to_string(longest) + " steps per segment): use shorter segments or a looser tolerance";
    } else {
      msg = "the residual went only from " + format_residual(so.residual_history.front()) + " at the guess to " +
            format_residual(out.residual_norm) + " x tolerance" + rank_note +
            ": the guess is too far for Newton's method; try a better guess, more segments, or continuation in a "
            "parameter from an easier problem";
    }
    return finish(ShootingStatus::NotConverged, msg);
  }
  return finish(ShootingStatus::Converged, "");
}


// One attempt with S segments of (nearly) equal length, started from the guess: from the guess's
// states at the segment starts, or the forward sweep's (opt.segment_starts).
template <class X>
ShootingResult<X> solve_with_segments(const typename SchemeFor<X>::BVP& bvp, const typename SchemeFor<X>::Guess& guess,
                                      int S, const ShootingOptions& opt) {
  using A = SchemeFor<X>;
  const int first = A::first_state(bvp), last = A::last_state(bvp);
  std::vector<int> starts;
  for (int i = 0; i <= S; ++i) starts.push_back(first + static_cast<int>(std::lround(double(last - first) * i / S)));
  const auto refs = A::states(bvp, guess, std::vector<int>(starts.begin(), starts.end() - 1));

  const bool sweep_first = S > 1 && opt.segment_starts == SegmentStarts::Propagated;
  ShootingResult<X> out = solve_from_starts<X>(bvp, sweep_first ? forward_sweep<X>(bvp, refs, starts, opt.step) : refs, starts, opt);
  out.propagated_starts = sweep_first;
  // Auto: when the guess's interior states did not lead to a solution, the forward sweep's may
  // (a stiff potential: the guess is far from the dynamics; an unstable flow: the sweep is not).
  // Not after a stall at the flows' roundoff floor (stalled_at_floor): that floor belongs to the
  // grid and the segments, not to the starts (the beanie at N = 10^6: ~17 minutes per attempt).
  if (S > 1 && opt.segment_starts == SegmentStarts::Auto && out.status == ShootingStatus::NotConverged &&
      !out.stalled_at_floor) {
    ShootingResult<X> swept = solve_from_starts<X>(bvp, forward_sweep<X>(bvp, refs, starts, opt.step), starts, opt);
    swept.propagated_starts = true;
    swept.iterations += out.iterations;
    // The better attempt's sentence stands; both accounts go to the detail.
    auto account = [](const char* from, const ShootingResult<X>& r) {
      return std::string("from ") + from + ": " + r.message + (r.detail.empty() ? "" : " [" + r.detail + "]");
    };
    if (swept.ok() || (swept.status == ShootingStatus::NotConverged && swept.residual_norm < out.residual_norm)) {
      swept.detail = swept.ok() ? "" : account("the forward sweep's segment starts", swept) + "; " +
                                           account("the guess's segment starts", out);
      out = std::move(swept);
    } else {
      out.detail = account("the guess's segment starts", out) + "; " + account("the forward sweep's segment starts", swept);
    }
  }
  out.segments = S;
  return out;
}

}  // namespace detail

// Solves the boundary value problem from a guess (e.g. interpolation of the boundary data, a
// previous solution resampled to this grid).
template <class X>
ShootingResult<X> solve_bvp_with(const typename SchemeFor<X>::BVP& bvp, const typename SchemeFor<X>::Guess& guess,
                                 const ShootingOptions& opt) {
  using A = SchemeFor<X>;
  const auto t0 = std::chrono::steady_clock::now();
  if (const std::string why = A::check(bvp, guess); !why.empty()) {
    ShootingResult<X> out;
    out.status = ShootingStatus::InvalidProblem;
    out.message = why;
    return out;
  }
  const int first = A::first_state(bvp), last = A::last_state(bvp);
  const int most = std::max(1, last - first);  // one step per segment at most
  int S = opt.method == ShootingMethod::Single ? 1
                                              : std::min(most, opt.segments > 0 ? opt.segments : auto_segments(bvp.N));
  const int doublings = opt.method == ShootingMethod::Single ? 0
                        : opt.segment_doublings >= 0   ? opt.segment_doublings
                        : opt.segments > 0             ? 0
                                                       : auto_segment_doublings;
  // An attempt that more segments may follow stops a crawling line search (SolverOptions::
  // stop_when_crawling): the spherical pendulum's windows on one 80-step segment at 1e-11 cut
  // the residual 4-fold in 47 line-search iterations before two segments converged in 4.
  auto attempt = [&](int segments, bool more_follow) {
    ShootingOptions o = opt;
    o.solver.stop_when_crawling = opt.solver.stop_when_crawling || more_follow;
    return detail::solve_with_segments<X>(bvp, guess, segments, o);
  };
  ShootingResult<X> out = attempt(S, doublings > 0 && S < most);
  // More segments when Newton did not converge from the guess for a reason they address: it
  // did not bring the residual down (a long segment amplifies the guess's error), or the flow
  // failed from the guess. Not after a stall at the roundoff floor
  // (finer segments do not lower it much, and a large solve would pay twice), nor for a rank
  // deficient Jacobian (the data are dependent).
  auto addressed = [](const ShootingResult<X>& r) {
    return (r.status == ShootingStatus::NotConverged && !r.stalled_at_floor) || r.status == ShootingStatus::FlowFailed;
  };
  std::string earlier;
  for (int d = 0; d < doublings && S < most && addressed(out); ++d) {
    earlier += (earlier.empty() ? "" : "; ") + std::string("with ") + std::to_string(S) + (S == 1 ? " segment: " : " segments: ") +
               out.message + (out.detail.empty() ? "" : " [" + out.detail + "]");
    S = std::min(most, 2 * S);
    ShootingResult<X> more = attempt(S, d + 1 < doublings && S < most);
    more.iterations += out.iterations;
    more.failed_segment_counts = out.failed_segment_counts;
    more.failed_segment_counts.push_back(out.segments);
    out = std::move(more);
  }
  if (!earlier.empty()) out.detail = (out.detail.empty() ? "" : out.detail + "; ") + "earlier attempts " + earlier;
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

template <class P>
ShootingResult<P> solve_bvp(const BoundaryValueProblem<P>& bvp, const ShootingGuess<P>& guess, const ShootingOptions& opt = {}) {
  return solve_bvp_with<P>(bvp, guess, opt);
}

// solve_bvp for the Galerkin schemes, with its start from a coarser grid: coarse_start.hpp.

inline const char* status_name(ShootingStatus s) {
  switch (s) {
    case ShootingStatus::Converged: return "converged";
    case ShootingStatus::NotConverged: return "not_converged";
    case ShootingStatus::RankDeficient: return "rank_deficient";
    case ShootingStatus::FlowFailed: return "flow_failed";
    case ShootingStatus::InvalidProblem: return "invalid_problem";
  }
  return "unknown";
}

}  // namespace lpshoot

#include "coarse_start.hpp"  // solve_bvp for the Galerkin schemes
