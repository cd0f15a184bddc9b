// Single and multiple shooting for discrete boundary value problems (METHOD.md §5).
//
// Unknowns: the extended state (flow state + absolute group element at its first node) at the
// start of each segment, in tangent coordinates around a reference (g = g_ref exp(x)). Residuals:
// initial constraints and conditions on the first segment's start, continuity defects (group parts
// in the tangent space) between segments, terminal conditions on the last segment's end. The
// Jacobian is exact: flow sensitivities (implicit function theorem) times automatic derivatives
// of the conditions; for multiple shooting it is block bidiagonal and the segments are propagated
// in parallel.
#pragma once

#include "boundary.hpp"
#include "nonlinear_solver.hpp"

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>

#include <algorithm>
#include <chrono>
#include <limits>
#include <thread>

namespace lpshoot {

enum class ShootingMethod { Single, Multiple };

// Multiple shooting: where segments 1, 2, ... start. Guess: the guess's states there. Propagated:
// the end of the previous segment run from its start (a forward sweep from the guess's initial
// state): the continuity defects vanish and the first Newton step is single shooting's. Auto:
// from the guess, and when that does not converge, again from the sweep (the sweep wins when the
// guess's interior states are far from the dynamics, e.g. a stiff potential; the guess when the
// flow is unstable or the guess is a near solution, e.g. a resampled one).
enum class SegmentStarts { Guess, Propagated, Auto };

struct ShootingOptions {
  ShootingMethod method = ShootingMethod::Single;
  int segments = 4;  // multiple shooting
  SegmentStarts segment_starts = SegmentStarts::Auto;
  SolverOptions solver;
  NewtonOptions step;
  double rank_tolerance = 1e-10;  // singular values of the equilibrated Jacobian below this times the largest count as zero
  int threads = 0;               // 0: one per available core
};

enum class ShootingStatus { Converged, NotConverged, RankDeficient, FlowFailed, InvalidProblem };

template <class P>
struct ShootingResult {
  ShootingStatus status = ShootingStatus::NotConverged;
  std::string message;
  int iterations = 0;
  std::vector<double> residual_history;
  double residual_norm = 0;
  double condition = 0;  // 1-norm condition estimate of the equilibrated shooting Jacobian at the solution
  double raw_residual_norm = 0;  // max-norm of the conditions in their own units
  // residual_norm: max over rows of |F_i| / tolerance_i (<= 1 at convergence); tolerance_i is the
  // solver tolerance plus the row's roundoff floor (see row_tolerances).
  int rank = 0, unknowns = 0;
  std::vector<std::string> dependent_conditions;  // when rank deficient
  std::vector<double> singular_values;            // of the equilibrated Jacobian, when rank deficient
  double wall_time_s = 0;
  Trajectory<P> trajectory;
  std::vector<GroupElement<P, double>> g;  // reconstructed g_0 .. g_N
  double cost = 0;                         // Σ L_d(a_n)
  double momentum_drift = 0;               // relative max |J_n - J_{k-1}|
  bool propagated_starts = false;          // multiple shooting started from the forward sweep
  bool ok() const { return status == ShootingStatus::Converged; }
};

const char* status_name(ShootingStatus s);

namespace detail {

// Block of scalar T from an extended boundary state seeded in all its tangent directions.
template <class P, class T>
NodeBlock<P, T> seeded_block(const BoundaryState<P>& x, GroupElement<P, T>& g_first) {
  using G = typename P::Group;
  using FS = FlowState<P>;
  constexpr int k = P::order, r = P::shape_dim, d = G::dim, m = P::num_constraints, ns = Dims<P>::state;
  NodeBlock<P, T> b;
  for (int i = 0; i < 2 * k; ++i)
    for (int a = 0; a < r; ++a) b.p[i](a) = T::variable(x.s.p[i](a), FS::p_offset(i) + a);
  for (int i = 0; i < 2 * k - 1; ++i) {
    typename G::template Tangent<T> delta;
    for (int a = 0; a < d; ++a) delta(a) = T::variable(0.0, FS::g_offset(i) + a);
    b.g[i] = G::compose(G::template cast<T>(x.s.g[i]), G::template exp<T>(delta));
  }
  for (int j = 0; j < k; ++j)
    for (int a = 0; a < m; ++a) b.lam[j](a) = T::variable(x.s.lam[j](a), FS::lam_offset(j) + a);
  b.p[2 * k] = b.p[2 * k - 1];
  b.g[2 * k - 1] = b.g[2 * k - 2];
  b.lam[k] = b.lam[k - 1];
  typename G::template Tangent<T> delta;
  for (int a = 0; a < d; ++a) delta(a) = T::variable(0.0, ns + a);
  g_first = G::compose(G::template cast<T>(x.g), G::template exp<T>(delta));
  return b;
}

// Values and Jacobian (rows x BoundaryState::size) of one end's conditions.
template <class P>
void boundary_block(const BoundaryValueProblem<P>& bvp, End e, const BoundaryState<P>& x, Eigen::VectorXd& R,
                    Eigen::MatrixXd* J) {
  constexpr int n = BoundaryState<P>::size;
  using T = Dual<double, n>;
  GroupElement<P, T> g;
  const NodeBlock<P, T> b = seeded_block<P, T>(x, g);
  const std::vector<T> res = boundary_residuals(bvp, e, b, g);
  R.resize(res.size());
  if (J) J->resize(res.size(), n);
  for (size_t i = 0; i < res.size(); ++i) {
    R(i) = res[i].v;
    if (J)
      for (int c = 0; c < n; ++c) (*J)(i, c) = res[i].d[c];
  }
}

// x = x_ref ⊕ δ on an extended state, and the right Jacobian of the retraction for each group
// block (so that d/dδ = d/d(tangent at x) · Jr).
template <class P>
BoundaryState<P> retract_extended(const BoundaryState<P>& ref, const Eigen::VectorXd& delta,
                                  Eigen::MatrixXd* Jr = nullptr) {
  using G = typename P::Group;
  using FS = FlowState<P>;
  constexpr int k = P::order, d = G::dim, ns = Dims<P>::state, n = BoundaryState<P>::size;
  BoundaryState<P> x;
  x.s = retract(ref.s, Vec<double, ns>(delta.head<ns>()));
  const typename G::template Tangent<double> dg = delta.segment<d>(ns);
  x.g = G::compose(ref.g, G::template exp<double>(dg));
  if (Jr) {
    Jr->setIdentity(n, n);
    auto block = [&](int off) {  // Jr(ξ) = d/dε log(exp(ξ)^{-1} exp(ξ + ε))
      using T = Dual<double, d>;
      typename G::template Tangent<T> xi;
      for (int a = 0; a < d; ++a) xi(a) = T::variable(delta(off + a), a);
      const auto e = G::log(G::compose(G::template cast<T>(G::inverse(G::template exp<double>(
                                           typename G::template Tangent<double>(delta.segment<d>(off))))),
                                       G::template exp<T>(xi)));
      for (int i = 0; i < d; ++i)
        for (int c = 0; c < d; ++c) (*Jr)(off + i, off + c) = e(i).d[c];
    };
    for (int i = 0; i < 2 * k - 1; ++i) block(FS::g_offset(i));
    block(ns);
  }
  return x;
}

template <class P>
Eigen::VectorXd extended_difference(const BoundaryState<P>& a, const BoundaryState<P>& b) {
  using G = typename P::Group;
  constexpr int ns = Dims<P>::state, n = BoundaryState<P>::size;
  Eigen::VectorXd v(n);
  v.head<ns>() = state_difference(a.s, b.s);
  v.tail<G::dim>() = G::log(G::compose(G::inverse(b.g), a.g));
  return v;
}

// Unknowns and continuity defects use a divided-difference basis: the 2k nodes, 2k-1 increments
// and k multipliers of a state are nearly equal neighbours (their differences scale like h^j),
// which makes nodal coordinates ill-conditioned (cond ~ h^{-(2k-1)}) and makes one tolerance
// mean very different things per component. Forward differences Δ^j / h^j (increments, already
// ~h: Δ^j / h^{j+1}) turn them into derivative-like quantities. M maps tangent coordinates to these.
template <class P>
Eigen::MatrixXd difference_basis(double h) {
  using FS = FlowState<P>;
  constexpr int k = P::order, r = P::shape_dim, d = P::Group::dim, m = P::num_constraints;
  constexpr int n = BoundaryState<P>::size;
  Eigen::MatrixXd M = Eigen::MatrixXd::Identity(n, n);
  auto block = [&](int off, int L, int c, int extra_power) {
    for (int j = 0; j < L; ++j) {
      const double scale = std::pow(h, -(j + extra_power));
      for (int i = 0; i <= j; ++i) {
        double binom = 1;
        for (int t = 0; t < i; ++t) binom = binom * (j - t) / (t + 1);
        for (int a = 0; a < c; ++a) M(off + j * c + a, off + i * c + a) = ((j - i) % 2 ? -1.0 : 1.0) * binom * scale;
      }
    }
  };
  block(FS::p_offset(0), 2 * k, r, 0);
  block(FS::g_offset(0), 2 * k - 1, d, 1);
  block(FS::lam_offset(0), k, m, 0);
  return M;
}

// The shooting equations for S >= 1 segments between state indices s_0 = k < s_1 < ... < s_S = N-k+1.
template <class P>
class ShootingSystem : public NonlinearSystem {
 public:
  static constexpr int n = BoundaryState<P>::size;
  ShootingSystem(const BoundaryValueProblem<P>& bvp, std::vector<BoundaryState<P>> refs, std::vector<int> starts,
                 const NewtonOptions& step, int threads)
      : bvp_(bvp), refs_(std::move(refs)), starts_(std::move(starts)), flow_(bvp.problem, bvp.h(), step),
        threads_(threads), M_(difference_basis<P>(bvp.h())), Minv_(M_.inverse()) {}

  int size() const override { return n * static_cast<int>(refs_.size()); }
  int segments() const { return static_cast<int>(refs_.size()); }

  // Residual rows may be scaled by w (none by default: the conditions are solved in their own units).
  bool residual(const Eigen::VectorXd& x, Eigen::VectorXd& F) override {
    if (!evaluate(x, F, nullptr)) return false;
    if (w_.size() == F.size()) F.array() *= w_.array();
    return true;
  }
  bool jacobian(const Eigen::VectorXd& x, Eigen::MatrixXd& J) override {
    Eigen::VectorXd F;
    if (!evaluate(x, F, &J)) return false;
    if (w_.size() == J.rows()) J = w_.asDiagonal() * J;
    return true;
  }
  void set_row_scaling(const Eigen::VectorXd& w) { w_ = w; }
  double progress_norm(const Eigen::VectorXd& F) const override {
    return w_.size() == F.size() ? F.cwiseQuotient(w_).lpNorm<Eigen::Infinity>() : F.lpNorm<Eigen::Infinity>();
  }

  // Per-row tolerances: `tol` plus the roundoff floor of each row, 64 u |J_δ| |state|: the
  // rounding of the state's values (magnitudes |state|) propagated through the row's derivative
  // with respect to them (J_δ: the raw Jacobian in tangent coordinates, at x). It covers the
  // divided differences of the continuity rows (the third divided difference of positions at
  // h = 0.0025 cannot be known better than ~1e-8) and the flow's amplification over a segment.
  Eigen::VectorXd row_tolerances(const Eigen::VectorXd& x, double tol) {
    using G = typename P::Group;
    using FS = FlowState<P>;
    constexpr int k = P::order, r = P::shape_dim, d = G::dim, m = P::num_constraints;
    const int S = segments();
    Eigen::VectorXd F;
    Eigen::MatrixXd J;
    const Eigen::VectorXd w = w_;
    w_.resize(0);
    const bool ok = evaluate(x, F, &J);
    w_ = w;
    Eigen::VectorXd t = Eigen::VectorXd::Constant(size(), tol);
    if (!ok) return t;
    Eigen::VectorXd mag(size());
    for (int i = 0; i < S; ++i) {
      const BoundaryState<P>& ref = refs_[i];
      Eigen::VectorXd v = Eigen::VectorXd::Ones(n);
      for (int j = 0; j < 2 * k; ++j) v.segment(FS::p_offset(j), r) = ref.s.p[j].cwiseAbs().array().max(1.0);
      for (int j = 0; j < 2 * k - 1; ++j) v.segment(FS::g_offset(j), d) = G::log(ref.s.g[j]).cwiseAbs().array().max(bvp_.h());
      for (int j = 0; j < k; ++j) v.segment(FS::lam_offset(j), m) = ref.s.lam[j].cwiseAbs().array().max(1.0);
      mag.segment(i * n, n) = v;
    }
    Eigen::MatrixXd Jd = J;  // J_x M = J_δ, per segment block of columns
    for (int i = 0; i < S; ++i) Jd.middleCols(i * n, n) = J.middleCols(i * n, n) * M_;
    constexpr double u = std::numeric_limits<double>::epsilon();
    const Eigen::ArrayXd floor = 64 * u * (Jd.cwiseAbs() * mag).array();
    t.array() += floor.min(1e4 * tol);  // at most four digits conceded to roundoff: beyond, not converged
    // A continuity row Δ^j/h^j of two nodal states cannot be known better than their rounding,
    // ~u |state| / h^j, whatever the tolerance (h = 5e-4, j = 3: ~2e-6 for |p| ~ 1). A defect at
    // that level means states equal to the last bit; this part is not capped.
    const int first_continuity = size() - (S - 1) * n - terminal_rows();
    for (int i = 0; i + 1 < S; ++i)
      t.segment(first_continuity + i * n, n).array() +=
          4 * u * (M_.cwiseAbs() * mag.segment((i + 1) * n, n)).array();
    return t;
  }

  // The conditions in their own units (no row scaling).
  bool raw_residual(const Eigen::VectorXd& x, Eigen::VectorXd& F) { return evaluate(x, F, nullptr); }

  // Runs all segments at x; fills the per-segment results. False if a flow failed.
  bool propagate(const Eigen::VectorXd& x, bool sensitivities, std::vector<FlowResult<P>>& runs,
                 std::vector<BoundaryState<P>>& starts, std::vector<Eigen::MatrixXd>& Jr) {
    const int S = segments();
    runs.resize(S);
    starts.resize(S);
    Jr.resize(S);
    for (int i = 0; i < S; ++i) {
      starts[i] = retract_extended(refs_[i], Eigen::VectorXd(Minv_ * x.segment(i * n, n)),
                                   sensitivities ? &Jr[i] : nullptr);
      if (sensitivities) Jr[i] = Jr[i] * Minv_;  // d(tangent at the start)/d(unknowns)
    }
    // The flow propagates the unknowns' own directions (Jr), not the nodal ones: a nodal
    // direction such as "move p_{2k-1} alone" is a (2k-1)-th difference of size h^{-(2k-1)}, whose
    // sensitivity (~N^{2k-1}) would be recombined into O(1) difference-basis entries afterwards by
    // cancellation, losing ~(2k-1) log10(1/h) digits twice (electron, N = 1000 in two segments:
    // Jacobian entries wrong by O(1) and Newton stalling on a linear problem).
    auto work = [&](int i) {
      const int N_local = starts_[i + 1] - starts_[i] + 2 * P::order - 1;
      runs[i] = flow_.run(starts[i].s, N_local, sensitivities ? &Jr[i] : nullptr, starts[i].g);
    };
    const int T = std::max(1, std::min(S, threads_ > 0 ? threads_ : static_cast<int>(std::thread::hardware_concurrency())));
    if (T == 1) {
      for (int i = 0; i < S; ++i) work(i);
    } else {
      std::vector<std::thread> pool;
      for (int t = 0; t < T; ++t)
        pool.emplace_back([&, t] {
          for (int i = t; i < S; i += T) work(i);
        });
      for (auto& th : pool) th.join();
    }
    last_failure_.clear();
    for (int i = 0; i < S; ++i)
      if (!runs[i].report.ok()) {
        last_failure_ = "segment " + std::to_string(i) + ": " + runs[i].report.message;
        return false;
      }
    return true;
  }

  const std::string& last_failure() const { return last_failure_; }
  const std::vector<int>& starts() const { return starts_; }
  const BoundaryValueProblem<P>& bvp() const { return bvp_; }
  std::vector<std::string> row_names() const {
    std::vector<std::string> names;
    for (int j = 0; j < P::order * P::num_constraints; ++j) names.push_back("initial constraint " + std::to_string(j));
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
  BoundaryState<P> end_state(const FlowResult<P>& run) const {
    const int N_local = run.trajectory.N();
    return {run.trajectory.state(N_local - P::order + 1), run.g_first};
  }

 private:
  // The conditions (unscaled) at x, with their Jacobian when J is given. The last evaluation is
  // kept: the solver asks again for what the setup (row tolerances) already computed at the guess.
  bool evaluate(const Eigen::VectorXd& x, Eigen::VectorXd& F, Eigen::MatrixXd* J) {
    const bool same_x = memo_x_.size() == x.size() && memo_x_ == x;
    if (same_x && (!J || memo_has_J_)) {
      if (!memo_ok_) return false;
      F = memo_F_;
      if (J) *J = memo_J_;
      return true;
    }
    memo_x_ = x;
    memo_has_J_ = J != nullptr;
    memo_ok_ = evaluate_uncached(x, F, J);
    if (memo_ok_) {
      memo_F_ = F;
      if (J) memo_J_ = *J;
    }
    return memo_ok_;
  }

  bool evaluate_uncached(const Eigen::VectorXd& x, Eigen::VectorXd& F, Eigen::MatrixXd* J) {
    std::vector<FlowResult<P>> runs;
    std::vector<BoundaryState<P>> starts;
    std::vector<Eigen::MatrixXd> Jr;
    if (!propagate(x, J != nullptr, runs, starts, Jr)) return false;
    const int S = segments(), N = size();
    F.resize(N);
    if (J) J->setZero(N, N);
    int row = 0;
    Eigen::VectorXd R;
    Eigen::MatrixXd JB;
    boundary_block(bvp_, End::Initial, starts[0], R, J ? &JB : nullptr);
    F.segment(row, R.size()) = R;
    if (J) J->block(row, 0, R.size(), n) = JB * Jr[0];
    row += R.size();
    for (int i = 0; i + 1 < S; ++i) {  // continuity: end of segment i minus start of segment i+1
      const BoundaryState<P> e = end_state(runs[i]);
      F.segment(row, n) = M_ * extended_difference(e, starts[i + 1]);
      if (J) {
        // d/d(end) of log(start^{-1} end) ≈ I and d/d(start) ≈ -I at the solution; exact forms:
        Eigen::MatrixXd De, Ds;
        difference_jacobians(e, starts[i + 1], De, Ds);
        J->block(row, i * n, n, n) = M_ * De * runs[i].sensitivity;
        J->block(row, (i + 1) * n, n, n) = M_ * Ds * Jr[i + 1];
      }
      row += n;
    }
    const BoundaryState<P> e = end_state(runs[S - 1]);
    boundary_block(bvp_, End::Terminal, e, R, J ? &JB : nullptr);
    F.segment(row, R.size()) = R;
    if (J) J->block(row, (S - 1) * n, R.size(), n) = JB * runs[S - 1].sensitivity;
    row += R.size();
    return row == N;
  }

  // Jacobians of extended_difference(a, b) with respect to right perturbations of a and of b.
  static void difference_jacobians(const BoundaryState<P>& a, const BoundaryState<P>& b, Eigen::MatrixXd& Da,
                                   Eigen::MatrixXd& Db) {
    using T = Dual<double, 2 * n>;
    using G = typename P::Group;
    constexpr int ns = Dims<P>::state;
    auto lift = [](const BoundaryState<P>& x, int off, NodeBlock<P, T>& blk, GroupElement<P, T>& g) {
      using FS = FlowState<P>;
      constexpr int k = P::order;
      for (int i = 0; i < 2 * k; ++i)
        for (int c = 0; c < P::shape_dim; ++c) blk.p[i](c) = T::variable(x.s.p[i](c), off + FS::p_offset(i) + c);
      for (int i = 0; i < 2 * k - 1; ++i) {
        typename G::template Tangent<T> dl;
        for (int c = 0; c < G::dim; ++c) dl(c) = T::variable(0.0, off + FS::g_offset(i) + c);
        blk.g[i] = G::compose(G::template cast<T>(x.s.g[i]), G::template exp<T>(dl));
      }
      for (int j = 0; j < k; ++j)
        for (int c = 0; c < P::num_constraints; ++c) blk.lam[j](c) = T::variable(x.s.lam[j](c), off + FS::lam_offset(j) + c);
      typename G::template Tangent<T> dl;
      for (int c = 0; c < G::dim; ++c) dl(c) = T::variable(0.0, off + ns + c);
      g = G::compose(G::template cast<T>(x.g), G::template exp<T>(dl));
    };
    NodeBlock<P, T> ba, bb;
    GroupElement<P, T> ga, gb;
    lift(a, 0, ba, ga);
    lift(b, n, bb, gb);
    std::vector<T> v;
    constexpr int k = P::order;
    for (int i = 0; i < 2 * k; ++i)
      for (int c = 0; c < P::shape_dim; ++c) v.push_back(ba.p[i](c) - bb.p[i](c));
    for (int i = 0; i < 2 * k - 1; ++i) {
      const auto l = G::log(G::compose(G::inverse(bb.g[i]), ba.g[i]));
      for (int c = 0; c < G::dim; ++c) v.push_back(l(c));
    }
    for (int j = 0; j < k; ++j)
      for (int c = 0; c < P::num_constraints; ++c) v.push_back(ba.lam[j](c) - bb.lam[j](c));
    const auto l = G::log(G::compose(G::inverse(gb), ga));
    for (int c = 0; c < G::dim; ++c) v.push_back(l(c));
    Da.resize(n, n);
    Db.resize(n, n);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < n; ++c) {
        Da(i, c) = v[i].d[c];
        Db(i, c) = v[i].d[n + c];
      }
  }

  BoundaryValueProblem<P> bvp_;
  std::vector<BoundaryState<P>> refs_;
  std::vector<int> starts_;
  DiscreteFlow<P> flow_;
  int threads_;
  std::string last_failure_;
  Eigen::MatrixXd M_, Minv_;
  Eigen::VectorXd w_;
  Eigen::VectorXd memo_x_, memo_F_;
  Eigen::MatrixXd memo_J_;
  bool memo_has_J_ = false, memo_ok_ = false;
};

}  // namespace detail

// An initial guess: a full discrete trajectory (p_0..p_N, g~_0..g~_{N-1}, λ^0..λ^{N-k}) and g_0.
template <class P>
struct ShootingGuess {
  Trajectory<P> trajectory;
  GroupElement<P, double> g0 = P::Group::template identity<double>();
};

namespace detail {

// Segment starts by a forward sweep: segment i+1 begins where segment i, run from its start,
// ends (stops at the first segment whose flow fails, keeping the given starts from there on).
template <class P>
std::vector<BoundaryState<P>> forward_sweep(const BoundaryValueProblem<P>& bvp, std::vector<BoundaryState<P>> refs,
                                            const std::vector<int>& starts, const NewtonOptions& step) {
  constexpr int k = P::order;
  const DiscreteFlow<P> flow(bvp.problem, bvp.h(), step);
  for (size_t i = 0; i + 1 < refs.size(); ++i) {
    const int N_local = starts[i + 1] - starts[i] + 2 * k - 1;
    const auto run = flow.run(refs[i].s, N_local, nullptr, refs[i].g);
    if (!run.report.ok()) break;
    refs[i + 1] = {run.trajectory.state(N_local - k + 1), run.g_first};
  }
  return refs;
}

// One shooting solve from the given segment start states (the unknowns start at 0).
template <class P>
ShootingResult<P> solve_from_starts(const BoundaryValueProblem<P>& bvp, const std::vector<BoundaryState<P>>& refs,
                                    const std::vector<int>& starts, const ShootingOptions& opt) {
  using G = typename P::Group;
  constexpr int k = P::order;
  const int S = static_cast<int>(refs.size());
  const auto t0 = std::chrono::steady_clock::now();
  ShootingResult<P> out;
  auto finish = [&](ShootingStatus st, std::string msg) {
    out.status = st;
    out.message = std::move(msg);
    out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  };
  ShootingSystem<P> system(bvp, refs, starts, opt.step, opt.threads);
  out.unknowns = system.size();

  Eigen::VectorXd x = Eigen::VectorXd::Zero(system.size());
  {  // The guess must be evaluable.
    Eigen::VectorXd F0;
    if (!system.residual(x, F0))
      return finish(ShootingStatus::FlowFailed, "the discrete flow failed from the initial guess: " + system.last_failure());
  }
  // Rows scaled by 1/(their tolerance): the solver then stops at a max-norm of 1.
  system.set_row_scaling(system.row_tolerances(x, opt.solver.tolerance).cwiseInverse());
  SolverOptions scaled = opt.solver;
  scaled.tolerance = 1.0;
  const SolverOutcome so = solve_nonlinear(system, x, scaled);
  out.iterations = so.iterations;
  out.residual_history = so.residual_history;
  out.residual_norm = so.residual_norm;

  // The trajectory at the final iterate.
  std::vector<FlowResult<P>> runs;
  std::vector<BoundaryState<P>> st;
  std::vector<Eigen::MatrixXd> Jr;
  if (!system.propagate(x, false, runs, st, Jr))
    return finish(ShootingStatus::FlowFailed, "the discrete flow failed at the final iterate: " + system.last_failure());
  Trajectory<P>& tr = out.trajectory;
  tr = runs[0].trajectory;
  for (int i = 1; i < S; ++i) {  // append the nodes each later segment adds
    const Trajectory<P>& t = runs[i].trajectory;
    const int skip_p = 2 * k, skip_g = 2 * k - 1, skip_l = k;
    tr.p.insert(tr.p.end(), t.p.begin() + skip_p, t.p.end());
    tr.g.insert(tr.g.end(), t.g.begin() + skip_g, t.g.end());
    tr.lam.insert(tr.lam.end(), t.lam.begin() + skip_l, t.lam.end());
  }
  out.g = reconstruct_group(bvp.problem, tr, st[0].g);
  {
    Eigen::VectorXd F;
    out.raw_residual_norm = system.raw_residual(x, F) ? F.lpNorm<Eigen::Infinity>() : INFINITY;
  }
  for (int j = 0; j + k <= tr.N(); ++j) out.cost += bvp.problem.lagrangian(tr.window_at(j), tr.h);
  if constexpr (G::dim > 0) out.momentum_drift = momentum_drift(bvp.problem, tr, st[0].g);

  // Conditioning and rank of the shooting Jacobian at the final iterate.
  Eigen::MatrixXd J;
  if (system.jacobian(x, J)) {  // equilibrate rows and columns for the rank decision
    for (int r = 0; r < J.rows(); ++r) {
      const double norm = J.row(r).lpNorm<Eigen::Infinity>();
      if (norm > 0) J.row(r) /= norm;
    }
    Eigen::VectorXd cs(J.cols());
    for (int c = 0; c < J.cols(); ++c) cs(c) = J.col(c).lpNorm<Eigen::Infinity>() > 0 ? 1.0 / J.col(c).lpNorm<Eigen::Infinity>() : 1.0;
    J = J * cs.asDiagonal();
    // Rank by column-pivoted QR (cheap); the SVD only when the rank is deficient, to name the
    // dependent conditions. Condition: 1-norm estimate from the LU.
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(J);
    const Eigen::VectorXd rdiag = qr.matrixR().diagonal().cwiseAbs();
    out.rank = 0;
    for (int i = 0; i < rdiag.size(); ++i)
      if (rdiag(i) > opt.rank_tolerance * rdiag(0)) ++out.rank;
    const double rc = Eigen::PartialPivLU<Eigen::MatrixXd>(J).rcond();
    out.condition = rc > 0 ? 1.0 / rc : INFINITY;
    if (out.rank < out.unknowns) {
      Eigen::BDCSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinU);
      const auto& sv = svd.singularValues();
      out.singular_values = std::vector<double>(sv.data(), sv.data() + sv.size());
      int rank = 0;
      for (int i = 0; i < sv.size(); ++i)
        if (sv(i) > opt.rank_tolerance * sv(0)) ++rank;
      out.rank = std::min(out.rank, rank);
      const auto names = system.row_names();
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
    }
  }
  const std::string solver_msg = so.message.empty() ? std::string("the solver did not converge") : so.message + " x tolerance";
  // A solver that ran away from the guess leaves a Jacobian whose rank says nothing about the data.
  const bool diverged = so.status != SolverStatus::Converged && !so.residual_history.empty() &&
                        !(out.residual_norm <= so.residual_history.front());
  // Nor does one where the flow has blown up (conditions off by more than 1e3 in their own units,
  // e.g. a stiff potential from a poor guess): that is a failure to converge, whatever the rank.
  const bool far = so.status != SolverStatus::Converged && !(out.raw_residual_norm <= 1e3);
  if (out.rank < out.unknowns && !diverged && !far) {
    std::string msg = "the shooting Jacobian is rank deficient (rank " + std::to_string(out.rank) + " of " +
                      std::to_string(out.unknowns) +
                      "): redundant or inconsistent boundary data, or a discrete problem that is (nearly) singular at "
                      "this step size; dependent: ";
    for (size_t i = 0; i < out.dependent_conditions.size() && i < 3; ++i) msg += (i ? "; " : "") + out.dependent_conditions[i];
    if (out.dependent_conditions.size() > 3)
      msg += "; and " + std::to_string(out.dependent_conditions.size() - 3) + " more";
    if (so.status != SolverStatus::Converged) msg += " (" + solver_msg + ")";
    return finish(ShootingStatus::RankDeficient, msg);
  }
  if (so.status != SolverStatus::Converged) {
    std::string msg = solver_msg;
    if (diverged)
      msg += "; the residual grew from " + format_residual(so.residual_history.front()) + " at the guess to " +
             format_residual(out.residual_norm) + (out.rank < out.unknowns ? ", and the Jacobian there has rank " +
                                                       std::to_string(out.rank) + " of " + std::to_string(out.unknowns)
                                                                           : std::string()) +
             ": try multiple shooting with more segments, a smaller h, or a better guess";
    else if (out.residual_norm < 1e3 && !so.residual_history.empty() &&
             so.residual_history.front() > 1e3 * out.residual_norm) {
      int longest = 0;
      for (int i = 0; i < S; ++i) longest = std::max(longest, starts[i + 1] - starts[i]);
      msg += "; it stalled close to the tolerance after a " + format_residual(so.residual_history.front() / out.residual_norm) +
             "-fold reduction: the roundoff floor of the flow on this grid (h = " + format_residual(bvp.h()) + ", " +
             std::to_string(longest) + " steps per segment): use shorter segments or a looser tolerance";
    } else if (!so.residual_history.empty()) {
      msg += "; the residual went from " + format_residual(so.residual_history.front()) + " at the guess to " +
             format_residual(out.residual_norm) +
             ": the guess is too far for Newton's method; try a better guess, more segments, or continuation "
             "in a parameter from an easier problem";
      if (out.rank < out.unknowns)
        msg += " (the Jacobian there has rank " + std::to_string(out.rank) + " of " + std::to_string(out.unknowns) + ")";
    }
    return finish(ShootingStatus::NotConverged, msg);
  }
  return finish(ShootingStatus::Converged, "");
}

}  // namespace detail

// Solves the boundary value problem from a guess (e.g. interpolation of the boundary data, a
// previous solution resampled to this grid).
template <class P>
ShootingResult<P> solve_bvp(const BoundaryValueProblem<P>& bvp, const ShootingGuess<P>& guess,
                            const ShootingOptions& opt = {}) {
  constexpr int k = P::order;
  const auto t0 = std::chrono::steady_clock::now();
  auto invalid = [&](std::string msg) {
    ShootingResult<P> out;
    out.status = ShootingStatus::InvalidProblem;
    out.message = std::move(msg);
    return out;
  };
  if (const std::string why = check_counting(bvp); !why.empty()) return invalid(why);
  if (guess.trajectory.N() != bvp.N || static_cast<int>(guess.trajectory.lam.size()) != bvp.N - k + 1)
    return invalid("the initial guess has N = " + std::to_string(guess.trajectory.N()) + ", the problem N = " +
                   std::to_string(bvp.N));
  // Segment starts (state indices) and reference states from the guess.
  const int first = k, last = bvp.N - k + 1;
  const int S = opt.method == ShootingMethod::Single ? 1 : std::max(1, std::min(opt.segments, last - first));
  std::vector<int> starts;
  for (int i = 0; i <= S; ++i) starts.push_back(first + static_cast<int>(std::lround(double(last - first) * i / S)));
  const auto g = reconstruct_group(bvp.problem, guess.trajectory, guess.g0);
  std::vector<BoundaryState<P>> refs;
  for (int i = 0; i < S; ++i) refs.push_back({guess.trajectory.state(starts[i]), g[starts[i] - k]});

  const bool sweep_first = S > 1 && opt.segment_starts == SegmentStarts::Propagated;
  ShootingResult<P> out =
      detail::solve_from_starts(bvp, sweep_first ? detail::forward_sweep(bvp, refs, starts, opt.step) : refs, starts, opt);
  out.propagated_starts = sweep_first;
  // Auto: when the guess's interior states did not lead to a solution, the forward sweep's may
  // (a stiff potential: the guess is far from the dynamics; an unstable flow: the sweep is not).
  if (S > 1 && opt.segment_starts == SegmentStarts::Auto && out.status == ShootingStatus::NotConverged) {
    ShootingResult<P> swept = detail::solve_from_starts(bvp, detail::forward_sweep(bvp, refs, starts, opt.step), starts, opt);
    swept.propagated_starts = true;
    swept.iterations += out.iterations;
    if (swept.ok() || (swept.status == ShootingStatus::NotConverged && swept.residual_norm < out.residual_norm)) {
      swept.message = swept.ok() ? "" : swept.message + " (from the guess's segment starts as well: " + out.message + ")";
      out = std::move(swept);
    } else {
      out.message += " (from the forward sweep's segment starts as well: " + swept.message + ")";
    }
  }
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

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
