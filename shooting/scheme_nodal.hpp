// The paper's nodal windows as a shooting scheme (METHOD.md §5): the flow state of
// DiscreteFlow<P> plus the group element at its first node, in tangent coordinates; the
// divided-difference basis for unknowns and defects; conditions with closures (boundary.hpp).
// The generic shooting system (shooting.hpp) asks a scheme for exactly what is below.
#pragma once

#include "boundary.hpp"

#include <Eigen/Core>

#include <cmath>
#include <string>
#include <vector>

namespace lpshoot {

template <class P>
struct ShootingGuess;  // shooting.hpp

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
  for (int i = 0; i < 2 * k; ++i) b.p_low[i] = x.s.p_low[i];
  b.p[2 * k] = b.p[2 * k - 1];
  b.p_low[2 * k] = b.p_low[2 * k - 1];
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

// The same from unknowns x in the difference basis (δ = Minv x). A problem that keeps its nodes'
// low parts (compensated.hpp) gets its nodes as ref + Σ_c Minv(·, c) x_c summed to twice the
// working precision: node j is Newton's forward formula Σ_i C(j, i) h^i x_i, whose terms are the
// differences the unknowns stand for, and rounding them as one δ_j would lose u |x_0| in every
// difference (the shooting unknowns' own roundoff floor).
template <class P>
BoundaryState<P> retract_from_basis(const BoundaryState<P>& ref, const Eigen::VectorXd& x, const Eigen::MatrixXd& Minv,
                                    Eigen::MatrixXd* Jr) {
  BoundaryState<P> out = retract_extended(ref, Eigen::VectorXd(Minv * x), Jr);
  if constexpr (keeps_low_parts<P>()) {
    using FS = FlowState<P>;
    constexpr int k = P::order, r = P::shape_dim;
    for (int i = 0; i < 2 * k; ++i)
      for (int a = 0; a < r; ++a) {
        const int row = FS::p_offset(i) + a;
        double sum = 0, err = 0;
        for (Eigen::Index c = 0; c < x.size(); ++c) {
          double t;
          two_sum(sum, Minv(row, c) * x(c), sum, t);
          err += t;
        }
        Vec<double, 1> hi(ref.s.p[i](a)), lo(ref.s.p_low[i](a));
        add_compensated(hi, lo, Vec<double, 1>(sum));
        add_compensated(hi, lo, Vec<double, 1>(err));
        out.s.p[i](a) = hi(0), out.s.p_low[i](a) = lo(0);
      }
  }
  return out;
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

// Jacobians of extended_difference(a, b) with respect to right perturbations of a and of b.
template <class P>
void difference_jacobians(const BoundaryState<P>& a, const BoundaryState<P>& b, Eigen::MatrixXd& Da,
                          Eigen::MatrixXd& Db) {
  constexpr int n = BoundaryState<P>::size;
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

}  // namespace detail

template <class P>
struct NodalScheme {
  using Key = P;
  using BVP = BoundaryValueProblem<P>;
  using Guess = ShootingGuess<P>;
  using Trajectory = lpshoot::Trajectory<P>;
  using State = BoundaryState<P>;
  using Flow = DiscreteFlow<P>;
  using Run = FlowResult<P>;
  using GroupElem = GroupElement<P, double>;
  static constexpr double roundoff_factor = 64;
  // What lifts the roundoff floor when the tolerance is below it (see row_tolerances).
  static constexpr const char* floor_remedy =
      "use shorter segments, fewer steps, a looser tolerance, or the Galerkin scheme (scheme.discretization), whose "
      "node states in increments have no such floor";
  static constexpr int size = BoundaryState<P>::size;
  static constexpr int k = P::order;

  // State index s: the flow state before step s (nodes s-k .. s+k-1); shooting spans k .. N-k+1.
  static int first_state(const BVP&) { return k; }
  static int last_state(const BVP& bvp) { return bvp.N - k + 1; }
  static std::string check(const BVP& bvp, const Guess& guess) {
    if (std::string why = check_counting(bvp); !why.empty()) return why;
    if (guess.trajectory.N() != bvp.N || static_cast<int>(guess.trajectory.lam.size()) != bvp.N - k + 1)
      return "the initial guess has N = " + std::to_string(guess.trajectory.N()) + ", the problem N = " +
             std::to_string(bvp.N);
    if (static_cast<int>(guess.trajectory.g.size()) != bvp.N)
      return "the initial guess has " + std::to_string(guess.trajectory.g.size()) + " group increments g~, expected N = " +
             std::to_string(bvp.N);
    return "";
  }
  // The guess's states at the given indices.
  static std::vector<State> states(const BVP& bvp, const Guess& guess, const std::vector<int>& at) {
    const auto g = reconstruct_group(bvp.problem, guess.trajectory, guess.g0);
    std::vector<State> out;
    for (int s : at) out.push_back({guess.trajectory.state(s), g[s - k]});
    return out;
  }
  static Flow flow(const BVP& bvp, const NewtonOptions& step) { return Flow(bvp.problem, bvp.h(), step); }
  // The closures' rows are not probed for linearity: every iteration evaluates its Jacobian.
  static bool affine(const BVP&, const NewtonOptions&) { return false; }
  // The nodal flow takes no guide (guide_bytes_per_step: 0): guided starts are written for the
  // Galerkin flows with a group only (galerkin_flow.hpp).
  static constexpr size_t guide_bytes_per_step = 0;
  static Run run(const Flow& flow, const State& start, int /*index*/, int steps, const Eigen::MatrixXd* seed,
                 const Run* /*guide*/ = nullptr, bool /*record*/ = false) {
    return flow.run(start.s, steps + 2 * k - 1, seed, start.g);
  }
  static State end_state(const Run& run) {
    return {run.trajectory.state(run.trajectory.N() - k + 1), run.g_first};
  }
  // x = ref ⊕ Minv x_basis (x_basis: unknowns in the difference basis).
  static State retract(const BVP&, const State& ref, const Eigen::VectorXd& x_basis, const Eigen::MatrixXd& Minv,
                       Eigen::MatrixXd* Jr) {
    return detail::retract_from_basis(ref, x_basis, Minv, Jr);
  }
  static Eigen::VectorXd difference(const BVP&, const State& a, const State& b) { return detail::extended_difference(a, b); }
  static void difference_jacobians(const BVP&, const State& a, const State& b, Eigen::MatrixXd& Da, Eigen::MatrixXd& Db) {
    detail::difference_jacobians(a, b, Da, Db);
  }
  static Eigen::MatrixXd basis(const BVP& bvp) { return detail::difference_basis<P>(bvp.h()); }
  // Magnitudes of the state's values (for the roundoff floor of rows). Nodes kept with their
  // low parts (compensated.hpp) are rounded like their increments, not like their values.
  static Eigen::VectorXd magnitudes(const BVP& bvp, const State& x) {
    using G = typename P::Group;
    using FS = FlowState<P>;
    constexpr int r = P::shape_dim, d = G::dim, m = P::num_constraints;
    Eigen::VectorXd v = Eigen::VectorXd::Ones(size);
    for (int j = 0; j < 2 * k; ++j) {
      if constexpr (keeps_low_parts<P>()) {
        const int i = j + 1 < 2 * k ? j : j - 1;
        v.segment(FS::p_offset(j), r) = (x.s.p[i + 1] - x.s.p[i]).cwiseAbs().array().max(bvp.h());
      } else {
        v.segment(FS::p_offset(j), r) = x.s.p[j].cwiseAbs().array().max(1.0);
      }
    }
    for (int j = 0; j < 2 * k - 1; ++j) v.segment(FS::g_offset(j), d) = G::log(x.s.g[j]).cwiseAbs().array().max(bvp.h());
    for (int j = 0; j < k; ++j) v.segment(FS::lam_offset(j), m) = x.s.lam[j].cwiseAbs().array().max(1.0);
    return v;
  }
  static void boundary_block(const BVP& bvp, End e, const State& x, Eigen::VectorXd& R, Eigen::MatrixXd* J) {
    detail::boundary_block(bvp, e, x, R, J);
  }
  static std::vector<std::string> initial_equation_names(const BVP&) {
    std::vector<std::string> names;
    for (int j = 0; j < k * P::num_constraints; ++j) names.push_back("initial constraint " + std::to_string(j));
    return names;
  }
  static std::string state_name() { return "flow state"; }

  // The whole trajectory from the segments' runs (each later run repeats the previous one's
  // last state: its first 2k nodes), g_0 .. g_N, the cost Σ L_d and the momentum drift.
  template <class Result>
  static void assemble(const BVP& bvp, const std::vector<Run>& runs, const State& first, Result& out) {
    Trajectory& tr = out.trajectory;
    tr = runs[0].trajectory;
    for (size_t i = 1; i < runs.size(); ++i) {
      const Trajectory& t = runs[i].trajectory;
      tr.p.insert(tr.p.end(), t.p.begin() + 2 * k, t.p.end());
      if (tr.has_low_parts() && t.has_low_parts()) tr.p_low.insert(tr.p_low.end(), t.p_low.begin() + 2 * k, t.p_low.end());
      tr.g.insert(tr.g.end(), t.g.begin() + 2 * k - 1, t.g.end());
      tr.lam.insert(tr.lam.end(), t.lam.begin() + k, t.lam.end());
    }
    out.g = reconstruct_group(bvp.problem, tr, first.g);
    out.cost = 0;
    for (int j = 0; j + k <= tr.N(); ++j) out.cost += bvp.problem.lagrangian(tr.window_at(j), tr.h);
    if constexpr (P::Group::dim > 0) out.momentum_drift = momentum_drift(bvp.problem, tr, first.g);
  }
};

}  // namespace lpshoot
