// The shooting equations (METHOD.md §5) for any discretization, through its scheme adapter A
// (scheme_nodal.hpp: the paper's windows; scheme_galerkin.hpp: Galerkin on node states).
//
// Unknowns: the extended state (flow state + group element) at the start of each segment, in
// the scheme's basis M around a reference state (x = ref ⊕ M^{-1} u). Residuals: the initial
// rows (the first state's own equations and the initial conditions), the continuity defects
// M (end of segment i ⊖ start of segment i+1) (group parts in the tangent space), the terminal
// conditions on the last segment's end. The Jacobian is exact: flow sensitivities (implicit
// function theorem) times automatic derivatives of the conditions; it is block bidiagonal, kept
// sparse (n x n blocks: memory linear in the number of segments), and the segments are
// propagated in parallel.
#pragma once

#include "band_lu.hpp"
#include "huge_pages.hpp"
#include "nonlinear_solver.hpp"
#include "scheme_galerkin.hpp"
#include "scheme_nodal.hpp"

#include <Eigen/LU>
#include <Eigen/SparseCore>

#include <algorithm>
#include <limits>
#include <exception>
#include <functional>
#include <system_error>
#include <thread>

namespace lpshoot {

template <class P>
struct ShootingGuess {  // the paper's scheme: a full discrete trajectory and g_0
  Trajectory<P> trajectory;
  GroupElement<P, double> g0 = P::Group::template identity<double>();
};

// The scheme adapter of a key: a discrete problem P (the paper's windows), or Galerkin<C, S, Q>.
template <class X>
struct SchemeOf {
  using type = NodalScheme<X>;
};
template <class C, int S, int Q>
struct SchemeOf<Galerkin<C, S, Q>> {
  using type = GalerkinScheme<Galerkin<C, S, Q>>;
};
template <class X>
using SchemeFor = typename SchemeOf<X>::type;

namespace detail {

// A square matrix whose column block i (n columns from i n) is the dense [top_i; bottom_i] from
// row first_row_i, written straight into compressed column storage (no triplets, no sort).
template <int n>
void write_block_columns(SparseJacobian& J, int N, const std::vector<int>& first_row,
                         const std::vector<Eigen::MatrixXd>& top, const std::vector<Eigen::MatrixXd>& bottom) {
  const int S = static_cast<int>(first_row.size());
  Eigen::Index nnz = 0;
  for (int i = 0; i < S; ++i) nnz += (top[i].rows() + bottom[i].rows()) * n;
  J.resize(N, N);  // compressed, no entries
  J.resizeNonZeros(nnz);
  advise_huge_pages(J.valuePtr(), static_cast<std::size_t>(nnz) * sizeof(double));
  advise_huge_pages(J.innerIndexPtr(), static_cast<std::size_t>(nnz) * sizeof(int));
  int* outer = J.outerIndexPtr();
  int* inner = J.innerIndexPtr();
  double* value = J.valuePtr();
  int k = 0;
  for (int i = 0; i < S; ++i) {
    const int t = static_cast<int>(top[i].rows()), b = static_cast<int>(bottom[i].rows());
    for (int c = 0; c < n; ++c) {
      outer[i * n + c] = k;
      for (int r = 0; r < t; ++r, ++k) inner[k] = first_row[i] + r, value[k] = top[i](r, c);
      for (int r = 0; r < b; ++r, ++k) inner[k] = first_row[i] + t + r, value[k] = bottom[i](r, c);
    }
  }
  outer[N] = k;
}

// The shooting equations for S >= 1 segments between state indices s_0 < s_1 < ... < s_S
// (s_0 = A::first_state, s_S = A::last_state).
template <class X>
class ShootingSystem : public NonlinearSystem {
 public:
  using A = SchemeFor<X>;
  using State = typename A::State;
  static constexpr int n = A::size;
  ShootingSystem(const typename A::BVP& bvp, std::vector<State> refs, std::vector<int> starts, const NewtonOptions& step,
                 int threads)
      : bvp_(bvp), refs_(std::move(refs)), starts_(std::move(starts)), flow_(A::flow(bvp, step)), threads_(threads),
        M_(A::basis(bvp)), Minv_(M_.inverse()) {}

  int size() const override { return n * static_cast<int>(refs_.size()); }
  int segments() const { return static_cast<int>(refs_.size()); }

  // Residual rows may be scaled by w (none by default: the conditions are solved in their own units).
  bool residual(const Eigen::VectorXd& x, Eigen::VectorXd& F) override {
    SparseJacobian J;
    if (!evaluate(x, F, expect_jacobian_ ? &J : nullptr)) return false;
    if (w_.size() == F.size()) F.array() *= w_.array();
    return true;
  }
  bool jacobian(const Eigen::VectorXd& x, SparseJacobian& J) override {
    Eigen::VectorXd F;
    if (!evaluate(x, F, &J)) return false;
    if (w_.size() == J.rows())
      for (int c = 0; c < J.outerSize(); ++c)
        for (SparseJacobian::InnerIterator it(J, c); it; ++it) it.valueRef() *= w_(it.row());
    return true;
  }
  // The unscaled Jacobian of the last evaluation that computed one, and where: at convergence,
  // the last Newton iterate's, one step from the solution, or two after a closing chord step
  // (kinsol_backend.cpp) (for diagnostics that need no exact
  // point: the rank and condition there are those of the solution to the digits reported).
  const SparseJacobian& last_jacobian() const { return last_J_; }
  // From the last Jacobian (the solve evaluates one at the guess first): the pattern is the same
  // at every evaluation (write_block_columns).
  Pattern pattern() const override {
    if (last_J_.rows() != size()) return {};
    const auto [kl, ku] = BandLU::bandwidths(last_J_);
    return {kl, ku, static_cast<long>(last_J_.nonZeros())};
  }
  const Eigen::VectorXd& last_jacobian_point() const { return last_J_x_; }
  void set_row_scaling(const Eigen::VectorXd& w) { w_ = w; }
  // The Jacobian at the next residual's point is computed with it (one seeded sweep) and kept.
  void expect_jacobian(bool yes) override { expect_jacobian_ = yes; }
  double progress_norm(const Eigen::VectorXd& F) const override {
    return w_.size() == F.size() ? F.cwiseQuotient(w_).lpNorm<Eigen::Infinity>() : F.lpNorm<Eigen::Infinity>();
  }

  // Per-row tolerances: `tol` plus the roundoff floor of each row, c u |J_δ| |state|: the
  // rounding of the state's values (magnitudes |state|) propagated through the row's derivative
  // with respect to them (J_δ: the raw Jacobian in tangent coordinates, at x). It covers the
  // differences in the continuity rows and the flow's amplification over a segment; c is the
  // scheme's (A::roundoff_factor: 64 for nodal windows, whose flow amplifies rounding like L^4
  // over L steps; 4 for the Galerkin increments, which do not).
  Eigen::VectorXd row_tolerances(const Eigen::VectorXd& x, double tol) {
    const int S = segments();
    Eigen::VectorXd F;
    SparseJacobian J;
    const Eigen::VectorXd w = w_;
    w_.resize(0);
    const bool ok = evaluate(x, F, &J);
    w_ = w;
    Eigen::VectorXd t = Eigen::VectorXd::Constant(size(), tol);
    if (!ok) return t;
    Eigen::VectorXd mag(size());
    for (int i = 0; i < S; ++i) mag.segment(i * n, n) = A::magnitudes(bvp_, refs_[i]);
    // |J_δ| |state| with J_δ = J_x diag(M, ..., M), block column by block column (the layout of
    // write_block_columns: column block i is one dense block of rows).
    constexpr double u = std::numeric_limits<double>::epsilon();
    Eigen::ArrayXd floor = Eigen::ArrayXd::Zero(size());
    for (int i = 0; i < S; ++i) {
      const int first = J.outerIndexPtr()[i * n], rows = J.outerIndexPtr()[i * n + 1] - first;
      const Eigen::Map<const Eigen::MatrixXd> B(J.valuePtr() + first, rows, n);
      floor.segment(J.innerIndexPtr()[first], rows) += ((B * M_).cwiseAbs() * mag.segment(i * n, n)).array();
    }
    floor *= A::roundoff_factor * u;
    t.array() += floor.min(1e4 * tol);  // at most four digits conceded to roundoff: beyond, not converged
    floor_ratio_ = floor.maxCoeff() / tol;
    // A continuity row of two states cannot be known better than their rounding, u |M| |state|,
    // whatever the tolerance (nodal windows, h = 5e-4, third differences: ~2e-6 for |p| ~ 1).
    // A defect at that level means states equal to the last bit; this part is not capped.
    const int first_continuity = size() - (S - 1) * n - terminal_rows();
    for (int i = 0; i + 1 < S; ++i)
      t.segment(first_continuity + i * n, n).array() += 4 * u * (M_.cwiseAbs() * mag.segment((i + 1) * n, n)).array();
    return t;
  }

  // The conditions in their own units (no row scaling).
  bool raw_residual(const Eigen::VectorXd& x, Eigen::VectorXd& F) { return evaluate(x, F, nullptr); }

  // The segment runs at x: those of the last evaluation when it was at x (moved out of the
  // memo, which keeps its residual and Jacobian), else propagated anew. Runs with sensitivities
  // are not reused: their steps are chord-solved to the step tolerance, and the trajectory a
  // solve returns comes from Newton-solved steps, accurate to roundoff, like its residual
  // (core/newton.hpp), so the memo is refreshed without sensitivities first.
  bool runs_at(const Eigen::VectorXd& x, std::vector<typename A::Run>& runs, std::vector<State>& starts) {
    if (memo_ok_ && memo_has_J_ && memo_x_.size() == x.size() && memo_x_ == x) {
      Eigen::VectorXd F;
      memo_has_J_ = false;
      memo_ok_ = evaluate_uncached(x, F, nullptr);
      if (memo_ok_) memo_F_ = F;
    }
    if (memo_ok_ && memo_x_.size() == x.size() && memo_x_ == x && !memo_runs_.empty()) {
      runs = std::move(memo_runs_);
      starts = std::move(memo_starts_);
      memo_runs_.clear();
      memo_starts_.clear();
      return true;
    }
    std::vector<Eigen::MatrixXd> Jr;
    return propagate(x, false, runs, starts, Jr);
  }

  // Runs all segments at x; fills the per-segment results. False if a flow failed.
  bool propagate(const Eigen::VectorXd& x, bool sensitivities, std::vector<typename A::Run>& runs,
                 std::vector<State>& starts, std::vector<Eigen::MatrixXd>& Jr) {
    const int S = segments();
    runs.resize(S);
    starts.resize(S);
    Jr.resize(S);
    for (int i = 0; i < S; ++i) {
      starts[i] = A::retract(bvp_, refs_[i], Eigen::VectorXd(x.segment(i * n, n)), Minv_, sensitivities ? &Jr[i] : nullptr);
      if (sensitivities) Jr[i] = Jr[i] * Minv_;  // d(tangent at the start)/d(unknowns)
    }
    // The flow propagates the unknowns' own directions (Jr), not the state's: in the nodal
    // scheme a direction such as "move p_{2k-1} alone" is a (2k-1)-th difference of size
    // h^{-(2k-1)}, whose sensitivity would be recombined into O(1) entries afterwards by
    // cancellation, losing ~(2k-1) log10(1/h) digits twice.
    // Each segment's flow is guided by its run at the last evaluation with sensitivities (the
    // previous Newton iterate's, near this one), and a run with sensitivities records the next
    // guide, within a memory budget (guides pay at coarse steps, where N is small).
    const bool record = sensitivities && A::guide_bytes_per_step > 0 &&
                        static_cast<double>(bvp_.N) * A::guide_bytes_per_step <= kGuideBudgetBytes;
    const bool guided = static_cast<int>(guides_.size()) == S;
    auto work = [&](int i) {
      runs[i] = A::run(flow_, starts[i], starts_[i], starts_[i + 1] - starts_[i], sensitivities ? &Jr[i] : nullptr,
                       guided ? &guides_[i] : nullptr, record);
    };
    const int T = std::max(1, std::min(S, threads_ > 0 ? threads_ : static_cast<int>(std::thread::hardware_concurrency())));
    if (T == 1) {
      for (int i = 0; i < S; ++i) {
        work(i);
        if (on_segment_) on_segment_(i + 1, S);
      }
    } else {
      // Stripe t of the segments on thread t; the calling thread takes stripe 0 and any stripe
      // whose thread could not be created (no thread is left unjoined, no exception escapes one).
      std::vector<std::exception_ptr> errors(T);
      auto stripe = [&](int t) {
        try {
          for (int i = t; i < S; i += T) {
            work(i);
            if (t == 0 && on_segment_) on_segment_(i + 1, S);
          }
        } catch (...) {
          errors[t] = std::current_exception();
        }
      };
      std::vector<std::thread> pool;
      try {
        for (int t = 1; t < T; ++t) pool.emplace_back(stripe, t);
      } catch (const std::system_error&) {  // e.g. EAGAIN under a thread or memory limit
      }
      const int started = static_cast<int>(pool.size()) + 1;
      stripe(0);
      for (int t = started; t < T; ++t) stripe(t);
      for (auto& th : pool) th.join();
      for (const auto& e : errors)
        if (e) std::rethrow_exception(e);
    }
    last_failure_.clear();
    for (int i = 0; i < S; ++i)
      if (!runs[i].report.ok()) {
        last_failure_ = "segment " + std::to_string(i) + ": " + runs[i].report.message;
        return false;
      }
    if constexpr (A::guide_bytes_per_step > 0) {
      if (record) {
        guides_.resize(S);
        for (int i = 0; i < S; ++i) {
          guides_[i].trajectory.intervals = runs[i].trajectory.intervals;
          guides_[i].memo = std::move(runs[i].memo);
        }
      }
    }
    return true;
  }

  const std::string& last_failure() const { return last_failure_; }
  // The largest roundoff floor of a row over the tolerance, as estimated by row_tolerances: above
  // 1e4 the tolerance asks for digits the scheme cannot deliver on this grid.
  double floor_ratio() const { return floor_ratio_; }
  // Called on the calling thread as segments are propagated ("segment i of S"), for progress
  // displays of long evaluations; may throw (e.g. to stop on an interrupt).
  void set_on_segment(std::function<void(int, int)> f) { on_segment_ = std::move(f); }
  const std::vector<int>& starts() const { return starts_; }
  const typename A::BVP& bvp() const { return bvp_; }
  std::vector<std::string> row_names() const {
    std::vector<std::string> names = A::initial_equation_names(bvp_);
    for (const auto& c : bvp_.conditions)
      if (c.end == End::Initial) names.push_back(c.name);
    for (int i = 0; i + 1 < segments(); ++i)
      for (int a = 0; a < n; ++a) names.push_back("continuity " + std::to_string(i) + "." + std::to_string(a));
    for (const auto& c : bvp_.conditions)
      if (c.end == End::Terminal) names.push_back(c.name);
    return names;
  }
  int terminal_rows() const {
    return static_cast<int>(std::count_if(bvp_.conditions.begin(), bvp_.conditions.end(),
                                          [](const auto& c) { return c.end == End::Terminal; }));
  }

 private:
  // The conditions (unscaled) at x, with their Jacobian when J is given. The last evaluation is
  // kept: the solver asks again for what the setup (row tolerances) already computed at the guess.
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& F, SparseJacobian* J) {
    const bool same_x = memo_x_.size() == x.size() && memo_x_ == x;
    // A failure is reused only for the same kind of request: a sweep with sensitivities that
    // failed says nothing about one without (their steps solve differently: chord matrices,
    // guides). The beanie on Galerkin 6 at V = 3000 (1 - cos psi), one segment: the Jacobian at
    // the best iterate failed, and the residual there was then taken as not finite.
    if (same_x && (memo_ok_ ? !J || memo_has_J_ : memo_has_J_ == (J != nullptr))) {
      if (!memo_ok_) return false;
      F = memo_F_;
      if (J) *J = last_J_;
      return true;
    }
    memo_x_ = x;
    memo_has_J_ = J != nullptr;
    memo_ok_ = evaluate_uncached(x, F, J);
    if (memo_ok_) {
      memo_F_ = F;
      if (J) {
        last_J_ = *J;
        last_J_x_ = x;
      }
    }
    return memo_ok_;
  }

  bool evaluate_uncached(const Eigen::VectorXd& x, Eigen::VectorXd& F, SparseJacobian* J) {
    std::vector<typename A::Run>& runs = memo_runs_;
    std::vector<State>& starts = memo_starts_;
    std::vector<Eigen::MatrixXd> Jr;
    if (!propagate(x, J != nullptr, runs, starts, Jr)) {
      runs.clear();
      return false;
    }
    const int S = segments(), N = size();
    F.resize(N);
    // Column block i (segment i's unknowns) is nonzero in one range of rows: the conditions on
    // segment i's start (the initial rows, or continuity i-1) then those on its end (continuity
    // i, or the terminal rows). Each part is a dense block, zeros stored too: the pattern is the
    // same at every evaluation (the sparse factorization's analysis is reused).
    std::vector<Eigen::MatrixXd> top(J ? S : 0), bottom(J ? S : 0);
    std::vector<int> first_row(J ? S : 0);
    int row = 0;
    Eigen::VectorXd R;
    Eigen::MatrixXd JB;
    A::boundary_block(bvp_, End::Initial, starts[0], R, J ? &JB : nullptr);
    F.segment(row, R.size()) = R;
    if (J) top[0] = JB * Jr[0];
    row += R.size();
    for (int i = 0; i + 1 < S; ++i) {  // continuity: end of segment i minus start of segment i+1
      const State e = A::end_state(runs[i]);
      F.segment(row, n) = M_ * A::difference(bvp_, e, starts[i + 1]);
      if (J) {
        Eigen::MatrixXd De, Ds;
        A::difference_jacobians(bvp_, e, starts[i + 1], De, Ds);
        bottom[i] = M_ * De * runs[i].sensitivity;
        top[i + 1] = M_ * Ds * Jr[i + 1];
        first_row[i + 1] = row;
      }
      row += n;
    }
    const State e = A::end_state(runs[S - 1]);
    A::boundary_block(bvp_, End::Terminal, e, R, J ? &JB : nullptr);
    F.segment(row, R.size()) = R;
    if (J) bottom[S - 1] = JB * runs[S - 1].sensitivity;
    row += R.size();
    if (J && row == N) write_block_columns<n>(*J, N, first_row, top, bottom);
    return row == N;
  }

  typename A::BVP bvp_;
  std::vector<State> refs_;
  std::vector<int> starts_;
  typename A::Flow flow_;
  int threads_;
  std::string last_failure_;
  double floor_ratio_ = 0;
  std::function<void(int, int)> on_segment_;
  Eigen::MatrixXd M_, Minv_;
  Eigen::VectorXd w_;
  Eigen::VectorXd memo_x_, memo_F_;
  std::vector<typename A::Run> memo_runs_;
  std::vector<State> memo_starts_;
  static constexpr double kGuideBudgetBytes = 64.0 * (1 << 20);
  std::vector<typename A::Run> guides_;  // per segment, when recorded
  SparseJacobian last_J_;
  Eigen::VectorXd last_J_x_;
  bool memo_has_J_ = false, memo_ok_ = false;
  bool expect_jacobian_ = false;
};

}  // namespace detail
}  // namespace lpshoot
