// The discrete flow map (METHOD.md §3): from initial data (p_0 .. p_{2k-1}, g~_0 .. g~_{2k-2},
// λ^0 .. λ^{k-1}) the steps n = k .. N-k produce p_{2k} .. p_N, g~_{2k-1} .. g~_{N-1} and
// λ^k .. λ^{N-k}. Optionally propagates the sensitivity of the state (in tangent coordinates)
// with respect to any set of directions of the initial state.
#pragma once

#include "degree.hpp"
#include "paper_affine.hpp"
#include "step_solve.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

namespace lpshoot {

// A discrete reduced trajectory on the grid t_n = n h (n = 0..N).
template <class P>
struct Trajectory {
  double h = 0;
  std::vector<Vec<double, P::shape_dim>> p;            // p_0 .. p_N
  std::vector<GroupElement<P, double>> g;              // g~_0 .. g~_{N-1}
  std::vector<Vec<double, P::num_constraints>> lam;    // λ^0 .. λ^{N-k}
  // Low parts of p (compensated.hpp), one per node when the flow kept them (problems with
  // keeps_low_parts), else empty: read as zero. Whoever edits p drops them (clear()).
  std::vector<Vec<double, P::shape_dim>> p_low;
  bool has_low_parts() const { return !p_low.empty() && p_low.size() == p.size(); }
  int N() const { return static_cast<int>(p.size()) - 1; }
  double time(int n) const { return n * h; }

  // Window a_j = (p_j .. p_{j+k}, g~_j .. g~_{j+k-1}).
  Window<P, double> window_at(int j) const {
    Window<P, double> a;
    for (int i = 0; i <= P::order; ++i) a.p[i] = p[j + i];
    if (has_low_parts())
      for (int i = 0; i <= P::order; ++i) a.p_low[i] = p_low[j + i];
    for (int i = 0; i < P::order; ++i) a.g[i] = g[j + i];
    return a;
  }

  // The flow state before step n (nodes n-k .. n+k-1).
  FlowState<P> state(int n) const {
    constexpr int k = P::order;
    FlowState<P> s;
    for (int i = 0; i < 2 * k; ++i) s.p[i] = p[n - k + i];
    if (has_low_parts())
      for (int i = 0; i < 2 * k; ++i) s.p_low[i] = p_low[n - k + i];
    for (int i = 0; i < 2 * k - 1; ++i) s.g[i] = g[n - k + i];
    for (int j = 0; j < k; ++j) s.lam[j] = lam[n - k + j];
    return s;
  }
};

template <class P>
struct FlowResult {
  Trajectory<P> trajectory;  // up to the last completed step
  FlowReport report;
  // d(final state)/d(initial directions), Dims<P>::state x q, when a seed was given; with a
  // seed of Dims<P>::state + d rows, the last d rows are the group element at the state's first
  // node (right tangent coordinates), starting from g0.
  Eigen::MatrixXd sensitivity;
  // g at the first node of the final state (node N-2k+1), reconstructed from g0.
  GroupElement<P, double> g_first;
};

// W_0 = g~_0 A(p_0, p_1)^{-1} of a state (g_{n+1} = g_n W_n) and its Jacobian: right tangent of W
// with respect to (δp_0, δp_1, δ of g~_0) (d x (2r + d)).
template <class P>
GroupElement<P, double> first_increment(const P& problem, const FlowState<P>& s,
                                        Eigen::Matrix<double, P::Group::dim, 2 * P::shape_dim + P::Group::dim>* jac) {
  using G = typename P::Group;
  constexpr int r = P::shape_dim, d = G::dim, nv = 2 * r + d;
  auto W = [&](const auto& p0, const auto& p1, const auto& g) {
    return G::compose(g, G::inverse(connection(problem, p0, p1)));
  };
  const GroupElement<P, double> W0 = W(s.p[0], s.p[1], s.g[0]);
  if (jac) {
    using T = Dual<double, nv>;
    Vec<T, r> p0, p1;
    typename G::template Tangent<T> delta;
    for (int a = 0; a < r; ++a) {
      p0(a) = T::variable(s.p[0](a), a);
      p1(a) = T::variable(s.p[1](a), r + a);
    }
    for (int a = 0; a < d; ++a) delta(a) = T::variable(0.0, 2 * r + a);
    const auto g = G::compose(G::template cast<T>(s.g[0]), G::template exp<T>(delta));
    const auto diff = G::log(G::compose(G::template cast<T>(G::inverse(W0)), W(p0, p1, g)));
    for (int i = 0; i < d; ++i)
      for (int c = 0; c < nv; ++c) (*jac)(i, c) = diff(i).d[c];
  }
  return W0;
}

template <class P>
class DiscreteFlow {
 public:
  using D = Dims<P>;
  DiscreteFlow(const P& problem, double h, NewtonOptions options = {})
      : problem_(problem),
        h_(h),
        options_(options),
        affine_(options.reuse_constant_matrix && discrete_problem_is_quadratic(problem, h)) {}

  const P& problem() const { return problem_; }
  double h() const { return h_; }
  // The step equations are affine with one matrix for every step (degree.hpp), factored once.
  bool affine() const { return affine_; }

  // Runs to node N (steps n = k .. N-k). `seed` (state x q, optional) gives the initial
  // directions whose sensitivity is propagated to the final state.
  FlowResult<P> run(const FlowState<P>& initial, int N, const Eigen::MatrixXd* seed = nullptr,
                    const GroupElement<P, double>& g0 = P::Group::template identity<double>()) const {
    using G = typename P::Group;
    constexpr int k = D::k, r = D::r, d = D::d, m = D::m, ns = D::state;
    FlowResult<P> out;
    Trajectory<P>& tr = out.trajectory;
    FlowReport& rep = out.report;
    tr.h = h_;
    if (N < 2 * k - 1 || !(h_ > 0)) {
      rep.status = FlowStatus::InvalidInput;
      rep.message = "the flow needs h > 0 and N >= 2k-1 = " + std::to_string(2 * k - 1) +
                    " (got h = " + format_number(h_) + ", N = " + std::to_string(N) + ")";
      return out;
    }
    if (seed && seed->rows() != ns && seed->rows() != ns + d) {
      rep.status = FlowStatus::InvalidInput;
      rep.message = "sensitivity seed has " + std::to_string(seed->rows()) + " rows, expected " +
                    std::to_string(ns) + " or " + std::to_string(ns + d);
      return out;
    }
    const bool with_group = seed && seed->rows() == ns + d;
    out.g_first = g0;
    tr.p.assign(initial.p.begin(), initial.p.end());
    tr.g.assign(initial.g.begin(), initial.g.end());
    tr.lam.assign(initial.lam.begin(), initial.lam.end());
    if constexpr (keeps_low_parts<P>()) {
      tr.p_low.assign(initial.p_low.begin(), initial.p_low.end());
      tr.p_low.reserve(N + 1);
    }
    tr.p.reserve(N + 1);
    tr.g.reserve(N);
    tr.lam.reserve(N - k + 1);
    if (seed) out.sensitivity = *seed;

    FlowState<P> s = initial;
    Eigen::MatrixXd next;
    // With sensitivities, each step's exact matrix at its solution, factored: the next step's
    // Newton iterates with it first (newton_solve). Without, every step evaluates its own, unless
    // the steps are affine: then the matrix factored at the first step serves every step (its
    // chord step is the Newton step), and so does the sensitivity dz/d(state).
    ChordMatrix<D::unknowns> chord;
    ChordMatrix<D::unknowns>* const chord_used = seed || affine_ ? &chord : nullptr;
    Eigen::Matrix<double, D::unknowns, ns> dz;
    double condition = 0;  // dz's step matrix's
    bool dz_current = false;
    WindowHessianCarry<P> windows;  // each window's Hessian, shared by the k + 1 steps it enters
    // With sensitivities, each step's sensitivity evaluates window a_n at the solution anyway
    // (its gradient gives F there): a predicted end of the chord steps (newton.hpp) saves the
    // residual that would show it, and is confirmed there (confirm_predicted_step). Beanie
    // control at h = 0.01: three residuals per step before, two now.
    NewtonOptions step_options = options_;
    step_options.end_on_prediction = seed && !affine_ && uses_window_hessians<P>();
    // An affine flow without a group takes its steps after the first from the constant window
    // Hessian of step k's windows (paper_affine.hpp): no evaluation of the problem after step k.
    constexpr bool can_map = d == 0 && uses_window_hessians<P>() && !keeps_low_parts<P>();
    const bool maps = can_map && affine_;
    bool mapped = false;
    std::conditional_t<can_map, AffineWindowGradient<P>, bool> affine_gradient{};
    WindowHessianCarry<P>* const carry_used = seed || maps ? &windows : nullptr;
    for (int n = k; n <= N - k; ++n) {
      StepUnknowns<P> z;
      StepReport step;
      if constexpr (can_map) {
        if (mapped) step = solve_mapped_affine_paper_step(affine_gradient, chord, s, n, z, windows);
      }
      if (!mapped) step = solve_step(problem_, h_, s, n, step_options, z, chord_used, carry_used);
      if (!rep.add(step)) return out;
      // W of the state's first node (it does not depend on z): g_first's update, and with the
      // group seeded, its sensitivity's Jacobian JW.
      Eigen::Matrix<double, d, 2 * r + d> JW;
      const GroupElement<P, double> W_first = first_increment(problem_, s, with_group ? &JW : nullptr);
      if (seed) {
        // New state = shifted old state + z; the new rows come from the implicit function theorem.
        if (!dz_current) {
          dz = step_sensitivity(problem_, h_, s, z, &chord, &condition, &windows, n);
          dz_current = affine_;
          if (step.predicted && condition <= options_.max_condition &&
              !confirm_predicted_step(problem_, options_, s, chord, windows, n, z)) {
            // Not confirmed: Newton again from z, on the exact matrix just factored.
            NewtonOptions again = step_options;
            again.end_on_prediction = false;
            const StepUnknowns<P> from = z;
            --rep.steps;  // counted again by add
            if (!rep.add(solve_step(problem_, h_, s, n, again, z, &chord, &windows, &from))) return out;
            dz = step_sensitivity(problem_, h_, s, z, &chord, &condition, &windows, n);
          }
        }
        rep.max_condition = std::max(rep.max_condition, condition);
        if (!(condition <= options_.max_condition)) {  // regular at the predictor, not at the solution
          --rep.steps;
          rep.status = FlowStatus::Singular;
          rep.failed_step = n;
          rep.message = "step n=" + std::to_string(n) + ": " + singular_step_reason(condition, options_.max_condition);
          return out;
        }
        const Eigen::MatrixXd& S = out.sensitivity;
        next.resize(S.rows(), S.cols());
        using FS = FlowState<P>;
        Eigen::Matrix<double, d, d> AdW;
        if constexpr (d > 0) {  // g_{first+1} = g_first W_first: δ' = Ad_{W^{-1}} δ + J_W δ(p_0, p_1, g~_0)
          if (with_group) AdW = G::Ad(G::inverse(W_first));
        }
        // Column by column (each seed's column is contiguous): fixed-size products, no temporary
        // matrices; dz s_j as a sum of dz's columns (vectorized down each column).
        for (Eigen::Index j = 0; j < S.cols(); ++j) {
          const Eigen::Map<const Vec<double, ns>> sj(S.col(j).data());
          Eigen::Map<Vec<double, ns>> nj(next.col(j).data());
          Vec<double, D::unknowns> dzs = dz.col(0) * sj(0);
          for (int c = 1; c < ns; ++c) dzs += dz.col(c) * sj(c);
          nj.template segment<(2 * k - 1) * r>(FS::p_offset(0)) = sj.template segment<(2 * k - 1) * r>(FS::p_offset(1));
          nj.template segment<r>(FS::p_offset(2 * k - 1)) = dzs.template head<r>();
          if constexpr (k > 1 && d > 0)
            nj.template segment<(2 * k - 2) * d>(FS::g_offset(0)) = sj.template segment<(2 * k - 2) * d>(FS::g_offset(1));
          if constexpr (d > 0) nj.template segment<d>(FS::g_offset(2 * k - 2)) = dzs.template segment<d>(r);
          if constexpr (k > 1 && m > 0)
            nj.template segment<(k - 1) * m>(FS::lam_offset(0)) = sj.template segment<(k - 1) * m>(FS::lam_offset(1));
          if constexpr (m > 0) nj.template segment<m>(FS::lam_offset(k - 1)) = dzs.template tail<m>();
          if constexpr (d > 0) {
            if (with_group)
              next.col(j).template tail<d>() = AdW * S.col(j).template tail<d>() +
                                               JW.template leftCols<2 * r>() * sj.template segment<2 * r>(FS::p_offset(0)) +
                                               JW.template rightCols<d>() * sj.template segment<d>(FS::g_offset(0));
          }
        }
        out.sensitivity.swap(next);
      }
      if constexpr (can_map) {
        if (maps && !mapped) {  // step k's windows and their Hessian (with a seed, computed above)
          if (!seed) step_sensitivity(problem_, h_, s, z, &chord, nullptr, &windows, n);
          affine_gradient.set(windows.of(n), s, z);
          mapped = true;
        }
      }
      out.g_first = G::compose(out.g_first, W_first);
      // Shift the state and store the new unknowns.
      for (int i = 0; i + 1 < 2 * k; ++i) s.p[i] = s.p[i + 1];
      s.p[2 * k - 1] = z.p;
      for (int i = 0; i + 1 < 2 * k; ++i) s.p_low[i] = s.p_low[i + 1];
      s.p_low[2 * k - 1] = z.p_low;
      if constexpr (keeps_low_parts<P>()) tr.p_low.push_back(z.p_low);
      for (int i = 0; i + 1 < 2 * k - 1; ++i) s.g[i] = s.g[i + 1];
      s.g[2 * k - 2] = z.g;
      for (int j = 0; j + 1 < k; ++j) s.lam[j] = s.lam[j + 1];
      s.lam[k - 1] = z.lam;
      tr.p.push_back(z.p);
      tr.g.push_back(z.g);
      tr.lam.push_back(z.lam);
    }
    return out;
  }

 private:
  P problem_;
  double h_;
  NewtonOptions options_;
  bool affine_;
};

// Moves a state along tangent coordinates: p += δp, g~ <- g~ exp(δ), λ += δλ.
template <class P>
FlowState<P> retract(const FlowState<P>& s, const Vec<double, Dims<P>::state>& delta) {
  using G = typename P::Group;
  using FS = FlowState<P>;
  constexpr int k = P::order, r = P::shape_dim, d = G::dim, m = P::num_constraints;
  FlowState<P> out = s;
  for (int i = 0; i < 2 * k; ++i) {
    if constexpr (keeps_low_parts<P>())
      add_compensated(out.p[i], out.p_low[i], Vec<double, r>(delta.template segment<r>(FS::p_offset(i))));
    else
      out.p[i] += delta.template segment<r>(FS::p_offset(i));
  }
  for (int i = 0; i < 2 * k - 1; ++i) {
    const typename G::template Tangent<double> xi = delta.template segment<d>(FS::g_offset(i));
    out.g[i] = G::compose(out.g[i], G::template exp<double>(xi));
  }
  for (int j = 0; j < k; ++j) out.lam[j] += delta.template segment<m>(FS::lam_offset(j));
  return out;
}

// Tangent coordinates of a relative to b: the δ with retract(b, δ) = a (log of b^{-1} a).
template <class P>
Vec<double, Dims<P>::state> state_difference(const FlowState<P>& a, const FlowState<P>& b) {
  using G = typename P::Group;
  using FS = FlowState<P>;
  constexpr int k = P::order, r = P::shape_dim, d = G::dim, m = P::num_constraints;
  Vec<double, Dims<P>::state> delta;
  for (int i = 0; i < 2 * k; ++i) delta.template segment<r>(FS::p_offset(i)) = (a.p[i] - b.p[i]) + (a.p_low[i] - b.p_low[i]);
  for (int i = 0; i < 2 * k - 1; ++i)
    delta.template segment<d>(FS::g_offset(i)) = G::log(G::compose(G::inverse(b.g[i]), a.g[i]));
  for (int j = 0; j < k; ++j) delta.template segment<m>(FS::lam_offset(j)) = a.lam[j] - b.lam[j];
  return delta;
}

}  // namespace lpshoot
