// The Galerkin schemes (METHOD.md §9) as a shooting scheme: the state is one interval in
// increment form plus g at its base node; conditions on the end nodes (galerkin_boundary.hpp).
// Unknowns and continuity defects are in increments already (no node differences anywhere); the
// basis turns each shape component's (X2, V1) into the node's p'' and p''' so that one tolerance
// means the same for every row.
#pragma once

#include "galerkin_boundary.hpp"
#include "huge_pages.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace lpshoot {

template <class Sch>
struct GalerkinGuess {
  GalerkinTrajectory<Sch> trajectory;  // N intervals and g_0
};

template <class Sch>
struct GalerkinScheme {
  using Key = Sch;
  using G = typename Sch::Group;
  using BVP = GalerkinBVP<Sch>;
  using Guess = GalerkinGuess<Sch>;
  using Trajectory = GalerkinTrajectory<Sch>;
  struct State {
    Interval<Sch, double> iv;
    typename G::template Element<double> g;  // at the interval's base node
  };
  using Flow = GalerkinFlow<Sch>;
  using Run = GalerkinFlowResult<Sch>;
  using GroupElem = typename G::template Element<double>;
  static constexpr int r = Sch::r, d = Sch::d, ns = Sch::state;
  static constexpr double roundoff_factor = 4;
  static constexpr const char* floor_remedy = "use fewer steps or a looser tolerance";
  static constexpr int size = ns + d;

  // State index = interval index: shooting spans intervals 0 .. N-1.
  static int first_state(const BVP&) { return 0; }
  static int last_state(const BVP& bvp) { return bvp.N - 1; }
  static std::string check(const BVP& bvp, const Guess& guess) {
    if (std::string why = check_counting(bvp); !why.empty()) return why;
    if (guess.trajectory.N() != bvp.N)
      return "the initial guess has N = " + std::to_string(guess.trajectory.N()) + ", the problem N = " + std::to_string(bvp.N);
    return "";
  }
  static std::vector<State> states(const BVP&, const Guess& guess, const std::vector<int>& at) {
    const auto g = guess.trajectory.group();
    std::vector<State> out;
    for (int s : at) out.push_back({guess.trajectory.intervals[s], g[s]});
    return out;
  }
  static Flow flow(const BVP& bvp, const NewtonOptions& step) { return Flow(bvp.model, bvp.h(), step); }
  // Without a group, with a quadratic ℓ and linear constraints (core/degree.hpp), the shooting
  // conditions are affine: the flows' end states are affine in their starts, the fixed and natural
  // boundary rows are affine in the end intervals, and tangent coordinates are differences.
  static bool affine(const BVP& bvp, const NewtonOptions& step) {
    return Sch::d == 0 && step.reuse_constant_matrix && model_is_quadratic(bvp.model);
  }
  // A run with sensitivities can record a guide for the next run of its segment (GalerkinFlow::run):
  // its memory per step (none without a group, whose steps do not use one).
  static constexpr size_t guide_bytes_per_step = d > 0 ? sizeof(GalerkinStepMemo<Sch>) + sizeof(Interval<Sch, double>) : 0;
  // A run with sensitivities keeps only its last interval unless it records a guide: shooting
  // reads its end and sensitivity; the trajectory it returns comes from a run without
  // (ShootingSystem::runs_at). At N = 10⁶ that is a trajectory's worth of memory (~100 MB for the
  // electron) not written at every Jacobian.
  static Run run(const Flow& flow, const State& start, int index, int steps, const Eigen::MatrixXd* seed,
                 const Run* guide = nullptr, bool record = false) {
    return flow.run(start.iv, steps, seed, start.g, index, !seed || record, guide, record);
  }
  static State end_state(const Run& run) { return {run.trajectory.intervals.back(), run.g_last}; }

  // x = ref ⊕ δ, δ = Minv x_basis; Jr: d(tangent at x)/dδ (identity but for the group blocks).
  static State retract(const BVP& bvp, const State& ref, const Eigen::VectorXd& x_basis, const Eigen::MatrixXd& Minv,
                       Eigen::MatrixXd* Jr) {
    const Eigen::VectorXd delta = Minv * x_basis;
    const double h = bvp.h();
    State x;
    x.iv = lpshoot::retract(ref.iv, Vec<double, ns>(delta.head<ns>()), h);
    const typename G::template Tangent<double> dg = delta.segment<d>(ns);
    x.g = G::compose(ref.g, G::template exp<double>(dg));
    if (Jr) {
      Jr->setIdentity(size, size);
      if constexpr (d > 0) {
        // W <- W exp(h δ): the tangent coordinate moves by Jr(h δ) per unit δ; g likewise with Jr(δ).
        const typename G::template Tangent<double> w = h * delta.segment<d>(Sch::W_off);
        Jr->block(Sch::W_off, Sch::W_off, d, d) = right_jacobian<G, double>(w);
        Jr->block(ns, ns, d, d) = right_jacobian<G, double>(dg);
      }
    }
    return x;
  }
  static Eigen::VectorXd difference(const BVP& bvp, const State& a, const State& b) {
    Eigen::VectorXd v(size);
    v.head<ns>() = state_difference(a.iv, b.iv, bvp.h());
    v.tail<d>() = G::log(G::compose(G::inverse(b.g), a.g));
    return v;
  }
  // Jacobians of difference(a, b) with respect to the tangent coordinates of a and of b.
  static void difference_jacobians(const BVP& bvp, const State& a, const State& b, Eigen::MatrixXd& Da,
                                   Eigen::MatrixXd& Db) {
    Da.setIdentity(size, size);
    Db = -Eigen::MatrixXd::Identity(size, size);
    if constexpr (d > 0) {
      const double h = bvp.h();
      auto group_block = [&](const typename G::template Element<double>& ea, const typename G::template Element<double>& eb,
                             double scale, int off) {
        // e = log(eb^{-1} ea) / scale with ea <- ea exp(scale εa), eb <- eb exp(scale εb).
        using T = Dual<double, 2 * d>;
        typename G::template Tangent<T> ta, tb;
        for (int i = 0; i < d; ++i) {
          ta(i) = T::variable(0.0, i) * scale;
          tb(i) = T::variable(0.0, d + i) * scale;
        }
        const auto A = G::compose(G::template cast<T>(ea), G::template exp<T>(ta));
        const auto B = G::compose(G::template cast<T>(eb), G::template exp<T>(tb));
        const typename G::template Tangent<T> e = G::log(G::compose(G::inverse(B), A));
        for (int i = 0; i < d; ++i)
          for (int c = 0; c < d; ++c) {
            Da(off + i, off + c) = e(i).d[c] / scale;
            Db(off + i, off + c) = e(i).d[d + c] / scale;
          }
      };
      group_block(a.iv.W, b.iv.W, h, Sch::W_off);
      group_block(a.g, b.g, 1.0, ns);
    }
  }
  // Per shape component: (X2, V1) -> (p''(t_n), p'''(t_n)) = (6 X2 - 2 V1, (6 V1 - 12 X2) / h).
  static Eigen::MatrixXd basis(const BVP& bvp) {
    const double h = bvp.h();
    Eigen::MatrixXd M = Eigen::MatrixXd::Identity(size, size);
    for (int a = 0; a < r; ++a) {
      const int x2 = Sch::X2_off + a, v1 = Sch::V1_off + a;
      M(x2, x2) = 6, M(x2, v1) = -2;
      M(v1, x2) = -12 / h, M(v1, v1) = 6 / h;
    }
    return M;
  }
  static Eigen::VectorXd magnitudes(const BVP&, const State& x) {
    Eigen::VectorXd v = Eigen::VectorXd::Ones(size);
    v.segment<r>(Sch::x_off) = x.iv.x.cwiseAbs().array().max(1.0);
    v.segment<r>(Sch::v_off) = x.iv.v.cwiseAbs().array().max(1.0);
    v.segment<d>(Sch::Om_off) = x.iv.Om.cwiseAbs().array().max(1.0);
    v.segment<r>(Sch::X2_off) = x.iv.X2.cwiseAbs().array().max(1.0);
    v.segment<r>(Sch::V1_off) = x.iv.V1.cwiseAbs().array().max(1.0);
    v.segment<d>(Sch::O1_off) = x.iv.O1.cwiseAbs().array().max(1.0);
    v.segment<Sch::aux>(Sch::aux_off) = x.iv.w.cwiseAbs().array().max(1.0);
    return v;
  }
  // The rows that come from the action (natural conditions, the first interval's own equations)
  // and their derivatives from the end interval's gradient and Hessian (galerkin_end_rows); the
  // fixed rows in duals over the end state's tangent. Without J, in doubles.
  static void boundary_block(const BVP& bvp, End e, const State& x, Eigen::VectorXd& R, Eigen::MatrixXd* J) {
    if (!J) {
      const std::vector<double> res = galerkin_boundary_residuals(bvp, e, x.iv, x.g);
      R = Eigen::Map<const Eigen::VectorXd>(res.data(), static_cast<Eigen::Index>(res.size()));
      return;
    }
    using T = Dual<double, size>;
    const double h = bvp.h();
    const bool initial = e == End::Initial;
    bool from_action = initial && Sch::aux > 0;
    for (const auto& c : bvp.conditions) from_action = from_action || (c.end == e && c.kind == ConditionKind::Natural);
    Vec<T, Sch::unknowns> action_rows;
    if (from_action) {
      Vec<double, Sch::unknowns> Ra;
      Eigen::Matrix<double, Sch::unknowns, ns> Ja;
      galerkin_end_rows<Sch>(bvp.model, x.iv, h, initial, Ra, Ja);
      for (int i = 0; i < Sch::unknowns; ++i) {
        action_rows(i) = T(Ra(i));
        for (int c = 0; c < ns; ++c) action_rows(i).d[c] = Ja(i, c);  // none on g (the symmetry)
      }
    }
    Interval<Sch, T> iv = x.iv.template cast<T>();
    for (int a = 0; a < r; ++a) {
      iv.x(a) = T::variable(x.iv.x(a), Sch::x_off + a);
      iv.v(a) = T::variable(x.iv.v(a), Sch::v_off + a);
      iv.X2(a) = T::variable(x.iv.X2(a), Sch::X2_off + a);
      iv.V1(a) = T::variable(x.iv.V1(a), Sch::V1_off + a);
    }
    for (int a = 0; a < d; ++a) {
      iv.Om(a) = T::variable(x.iv.Om(a), Sch::Om_off + a);
      iv.O1(a) = T::variable(x.iv.O1(a), Sch::O1_off + a);
    }
    for (int a = 0; a < Sch::aux; ++a) iv.w(a) = T::variable(x.iv.w(a), Sch::aux_off + a);
    auto g = G::template cast<T>(x.g);
    if constexpr (d > 0) {
      typename G::template Tangent<T> dw, dg;
      for (int a = 0; a < d; ++a) {
        dw(a) = T::variable(0.0, Sch::W_off + a) * h;
        dg(a) = T::variable(0.0, ns + a);
      }
      iv.W = G::compose(iv.W, G::template exp<T>(dw));
      g = G::compose(g, G::template exp<T>(dg));
    }
    const std::vector<T> res = galerkin_boundary_residuals(bvp, e, iv, g, from_action ? &action_rows : nullptr);
    R.resize(res.size());
    J->resize(res.size(), size);
    for (size_t i = 0; i < res.size(); ++i) {
      R(i) = res[i].v;
      for (int c = 0; c < size; ++c) (*J)(i, c) = res[i].d[c];
    }
  }
  static std::vector<std::string> initial_equation_names(const BVP&) { return galerkin_initial_equation_names<Sch>(); }
  static std::string state_name() { return "interval"; }

  // The whole trajectory from the segments' runs (each later run starts with the previous one's
  // last interval), g_0 .. g_N, the cost Σ h Σ b_i ℓ and the momentum drift.
  template <class Result>
  static void assemble(const BVP& bvp, const std::vector<Run>& runs, const State& first, Result& out) {
    Trajectory& tr = out.trajectory;
    tr.h = bvp.h();
    tr.g0 = first.g;
    size_t total = 1;
    for (const auto& run : runs) total += run.trajectory.intervals.size() - 1;
    tr.intervals.reserve(total);  // one allocation (N up to 1e6: ~100 MB)
    advise_huge_pages(tr.intervals.data(), total * sizeof(tr.intervals[0]));
    tr.intervals = runs[0].trajectory.intervals;
    for (size_t i = 1; i < runs.size(); ++i) {
      const auto& t = runs[i].trajectory.intervals;
      tr.intervals.insert(tr.intervals.end(), t.begin() + 1, t.end());
    }
    out.g = tr.group();
    out.cost = 0;
    for (const auto& iv : tr.intervals) out.cost += interval_cost(bvp.model, iv, tr.h);
    out.momentum_drift = 0;
    if constexpr (d > 0) {
      const auto J = galerkin_spatial_momentum(bvp.model, tr);
      for (const auto& Jn : J) out.momentum_drift = std::max(out.momentum_drift, (Jn - J.front()).template lpNorm<Eigen::Infinity>());
      out.momentum_drift /= std::max(1.0, J.front().template lpNorm<Eigen::Infinity>());
    }
  }
};

}  // namespace lpshoot
