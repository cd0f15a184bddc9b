// The Galerkin flow map (METHOD.md §9): intervals one after another from a first interval, with
// the sensitivity of the last one to any seeded directions of the first, and what is read off
// a trajectory: nodes, the group element, the discrete momentum map, node controls.
#pragma once

#include "degree.hpp"
#include "galerkin_affine.hpp"
#include "galerkin_step.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

namespace lpshoot {

// A Galerkin trajectory on t_n = n h: intervals 0 .. N-1 (each with its base node n) and g_0.
template <class Sch>
struct GalerkinTrajectory {
  using G = typename Sch::Group;
  double h = 0;
  std::vector<Interval<Sch, double>> intervals;
  typename G::template Element<double> g0 = G::template identity<double>();

  int N() const { return static_cast<int>(intervals.size()); }
  double time(int n) const { return n * h; }
  Vec<double, Sch::r> x(int n) const { return n < N() ? intervals[n].x : intervals.back().x_end(h); }
  Vec<double, Sch::r> v(int n) const { return n < N() ? intervals[n].v : intervals.back().v_end(h); }
  Vec<double, Sch::d> Omega(int n) const { return n < N() ? intervals[n].Om : intervals.back().Om_end(h); }
  // g_0 .. g_N (g_{n+1} = g_n W_n).
  std::vector<typename G::template Element<double>> group() const {
    std::vector<typename G::template Element<double>> g{g0};
    g.reserve(intervals.size() + 1);
    for (const auto& iv : intervals) g.push_back(G::compose(g.back(), iv.W));
    return g;
  }
};

// One solved step of a flow with sensitivities, kept as a guide for a later flow near it:
// dz/d(state) and the step matrix ∂F/∂z at the solution, factored.
template <class Sch>
struct GalerkinStepMemo {
  Eigen::Matrix<double, Sch::unknowns, Sch::state> dz;
  ChordMatrix<Sch::unknowns> matrix;
};

template <class Sch>
struct GalerkinFlowResult {
  GalerkinTrajectory<Sch> trajectory;  // the start interval and every completed step's
  FlowReport report;
  // d(last interval)/d(seeded directions of the first): Sch::state rows, and d more (the group
  // element at the last interval's base node, right tangent) when the seed had them.
  Eigen::MatrixXd sensitivity;
  typename Sch::Group::template Element<double> g_last;  // g at the last interval's base node
  // Step k's memo at index k - 1, when the run recorded them (run's `record`, with a seed).
  std::vector<GalerkinStepMemo<Sch>> memo;
};

template <class Sch>
class GalerkinFlow {
 public:
  using Model = typename Sch::Model;
  using G = typename Sch::Group;
  GalerkinFlow(const Model& model, double h, NewtonOptions options = {})
      : model_(model), h_(h), options_(options), affine_(options.reuse_constant_matrix && model_is_quadratic(model)) {}

  const Model& model() const { return model_; }
  double h() const { return h_; }
  // The step equations are affine with one matrix for every step (degree.hpp), factored once.
  bool affine() const { return affine_; }

  // Takes `steps` steps from interval `start` (whose base node is node `first_node`, for
  // messages), g at its base node = g_start. `seed` (Sch::state or Sch::state + d rows) gives
  // the directions whose sensitivity is propagated. With keep = false only the last interval is
  // kept in the trajectory (memory O(1) in the steps).
  // `guide`: an earlier run of the same steps from a nearby start, with its memo (`record`, with
  // a seed, keeps one), e.g. the previous Newton iterate's in shooting. With a group, step k then
  // starts from the guide's interval k moved to first order by the change of interval k-1
  // (guide's dz), O(|change|²) off, with the guide's step matrix for its chord iterations.
  GalerkinFlowResult<Sch> run(const Interval<Sch, double>& start, int steps, const Eigen::MatrixXd* seed = nullptr,
                              const typename G::template Element<double>& g_start = G::template identity<double>(),
                              int first_node = 0, bool keep = true, const GalerkinFlowResult<Sch>* guide = nullptr,
                              bool record = false) const {
    constexpr int r = Sch::r, d = Sch::d, ns = Sch::state, nz = Sch::unknowns;
    GalerkinFlowResult<Sch> out;
    out.trajectory.h = h_;
    out.trajectory.g0 = g_start;
    out.g_last = g_start;
    FlowReport& rep = out.report;
    if (steps < 0 || !(h_ > 0)) {
      rep.status = FlowStatus::InvalidInput;
      rep.message = "the flow needs h > 0 and steps >= 0 (got h = " + format_number(h_) + ", steps = " +
                    std::to_string(steps) + ")";
      return out;
    }
    if (seed && seed->rows() != ns && seed->rows() != ns + d) {
      rep.status = FlowStatus::InvalidInput;
      rep.message = "sensitivity seed has " + std::to_string(seed->rows()) + " rows, expected " + std::to_string(ns) +
                    " or " + std::to_string(ns + d);
      return out;
    }
    const bool with_group = seed && seed->rows() == ns + d;
    auto& ivs = out.trajectory.intervals;
    if (keep) ivs.reserve(steps + 1);
    ivs.push_back(start);
    if (seed) out.sensitivity = *seed;
    Eigen::MatrixXd next;
    Interval<Sch, double> s = start;
    // With sensitivities, each step's exact matrix at its solution, factored: the next step's
    // Newton iterates with it first (newton_solve). Without, with a group, the last matrix a
    // step's Newton evaluated (a step matrix costs ~8 residuals there: beanie Galerkin 6, 128
    // against 15 µs); without a group every step evaluates its own (flat matrices are cheap).
    // Affine steps (no group, degree.hpp) after the first start from the step map's prediction
    // z_c + dz · state (dz the step sensitivity, z_c read off the first step, solved by Newton;
    // the map is the same at every step, ℓ not depending on time) and take one correction with
    // the first step's factored matrix, their residual from the constant interval Hessian
    // (solve_mapped_affine_step, galerkin_affine.hpp): no evaluation of the model after step 1.
    ChordMatrix<nz> chord;
    ChordMatrix<nz>* const chord_used = seed || d > 0 || affine_ ? &chord : nullptr;
    NewtonOptions step_options = options_;  // chord-ended steps of a trajectory: polished (newton.hpp)
    step_options.polish_chord = !seed && d > 0;
    // With sensitivities and a group, the step's sensitivity evaluates it at the solution
    // anyway: a predicted end of its chord steps is confirmed there (confirm_predicted_step).
    step_options.end_on_prediction = seed && d > 0;
    StepCarry<Sch> carry;  // interval derivatives shared by consecutive steps
    StepCarry<Sch>* const carry_used = &carry;
    Eigen::Matrix<double, nz, ns> dz;
    double condition = 0;  // dz's step matrix's
    bool dz_current = false;
    Vec<double, nz> z_c;
    bool mapped = false;  // z_c is known: later steps start from the affine map
    std::conditional_t<d == 0, AffineIntervalGradient<Sch>, bool> affine_gradient;  // set with z_c
    // With a group, later steps start from the extrapolation of the last intervals' unknowns
    // (extrapolate, quadratic from the third step): O(h³) off instead of O(h) for the last
    // interval's, about one Newton iteration fewer per step (beanie Galerkin 6, flows with
    // sensitivities: 4.6 -> 3.95 per step at N = 64, 3.9 -> 3.0 at N = 256). Without a group
    // (flat steps, cheap Jacobians) the last interval's: a fast-growing constrained flow
    // (tests/test_galerkin_flat.cpp) stalled at its noise from the extrapolation.
    Interval<Sch, double> before = start, earlier = start;  // intervals n-2 and n-3 (k >= 2, 3)
    // A guide's prediction is taken when its first-order move is small, |move_i| <= 0.3 (1 + |z_i|)
    // (a larger one is a poor linearization: beanie Galerkin 6 at N = 16, the second shooting
    // iterate's moves take 98 Newton iterations guided, 86 extrapolated), and while it was the
    // closer of the two predictions at the step before.
    const bool guided = d > 0 && guide && guide->memo.size() == static_cast<size_t>(steps) &&
                        guide->trajectory.intervals.size() == static_cast<size_t>(steps) + 1;
    bool guide_closer = true;
    // Steps taken on their prediction (with sensitivities and a group): when the step before
    // landed within 1/8 of the confirmation's bound (predicted_step_bound) of its prediction,
    // this step's prediction is not iterated on. The step is evaluated only where its sensitivity
    // evaluates it anyway, at the prediction, and confirmed there by one exact Newton correction
    // (confirm_predicted_step), as a predicted end of chord steps is. The predictions' errors
    // (extrapolation: O(h³); a guide: O(|change of start|²)) vary smoothly from step to step.
    // Beanie Galerkin 4 at h = 2e-5: predictions 2e-11 to 4e-11 off, the bound 1e-8 (the
    // noise's, cond ~2e6), and each step spent two residuals on chord steps to find that out.
    // One not confirmed is solved from there by Newton, as before.
    const bool predictions_taken = seed && d > 0 && !affine_;  // affine: one sensitivity per flow
    double last_prediction_error = std::numeric_limits<double>::infinity();
    if (record && seed) out.memo.reserve(steps);
    if constexpr (d == 0)
      if (affine_ && steps > 0) dz_current = affine_start(start, carry, chord, dz, condition);
    for (int k = 1; k <= steps; ++k) {
      Interval<Sch, double> z;
      Vec<double, nz> predicted, from_guide;
      if constexpr (d == 0) {
        if (mapped) predicted = z_c + dz * flat_interval_coordinates(s);
      }
      const bool extrapolated = d > 0 && k >= 2;
      if (extrapolated) predicted = extrapolate(k >= 3 ? &earlier : nullptr, before, s);
      bool use_guide = false;
      if (guided) {
        const GalerkinStepMemo<Sch>& m = guide->memo[k - 1];
        Interval<Sch, double> g = guide->trajectory.intervals[k];
        const Vec<double, nz> move = m.dz * state_difference(s, guide->trajectory.intervals[k - 1], h_);
        apply_galerkin_correction<Sch>(g, move, h_);
        from_guide = unknowns_relative_to(g, s);
        use_guide = guide_closer && (move.cwiseAbs().array() <= 0.3 * (1.0 + from_guide.cwiseAbs().array())).all();
        if (use_guide) chord = m.matrix;
      }
      const Vec<double, nz>* start_from = use_guide ? &from_guide : mapped || extrapolated ? &predicted : nullptr;
      const bool taken = predictions_taken && start_from &&
                         last_prediction_error <= predicted_step_bound(options_, condition) / 8;
      StepReport step;
      if (taken) {
        z = galerkin_step_start<Sch>(s, h_, start_from);
        step.step = first_node + k;
        step.status = StepStatus::Converged;
        step.predicted = true;
        step.condition = condition;
      } else if (mapped) {
        if constexpr (d == 0)
          step = solve_mapped_affine_step<Sch>(affine_gradient, chord, h_, s, predicted, first_node + k, z, carry);
      } else {
        step = solve_galerkin_step<Sch>(model_, h_, s, first_node + k, step_options, z, use_guide ? &chord : chord_used,
                                        carry_used, start_from);
        // Without sensitivities, a step that ended at its noise tells the next ones its size
        // (NewtonOptions::noise_floor): their chord steps end once they are well within it instead
        // of sampling it (beanie Galerkin 4 at h = 2e-5: 2.7 -> 2.0 iterations per step, and
        // no polishing corrections; the momentum drift unchanged).
        if (step.noise_sample > 0 && !seed) step_options.noise_floor = step.noise_sample;
      }
      if (!rep.add(step)) return out;
      if constexpr (d == 0)  // the carry held the start interval's derivatives (affine_start)
        if (affine_ && k == 1 && dz_current) carry.interval.gradient = flat_interval_gradient<Sch>(model_, z, h_);
      if (seed || affine_) {
        if (!dz_current) {
          Vec<double, nz> F_at_z;
          dz = galerkin_step_sensitivity<Sch>(model_, h_, s, z, &chord, &condition, carry_used,
                                              step.predicted ? &F_at_z : nullptr);
          dz_current = affine_;
          if (taken) rep.max_residual = std::max(rep.max_residual, F_at_z.template lpNorm<Eigen::Infinity>());
          if (step.predicted && condition <= options_.max_condition &&
              !confirm_predicted_step<Sch>(h_, options_, F_at_z, chord, z, carry_used)) {
            // Not confirmed: Newton again from z, on the exact matrix just factored. The carry
            // now holds interval n's derivatives, not the state's: this step goes without it.
            carry.valid = false;
            NewtonOptions again = step_options;
            again.end_on_prediction = false;
            const Vec<double, nz> from_z = unknowns_relative_to(z, s);
            --rep.steps;  // counted again by add
            if (!rep.add(solve_galerkin_step<Sch>(model_, h_, s, first_node + k, again, z, &chord, carry_used, &from_z)))
              return out;
            dz = galerkin_step_sensitivity<Sch>(model_, h_, s, z, &chord, &condition, carry_used);
          }
        }
        rep.max_condition = std::max(rep.max_condition, condition);
        if (predictions_taken)  // how far this step's solution lies from its prediction
          last_prediction_error = start_from ? relative_size<Sch>(unknowns_relative_to(z, s) - *start_from, z)
                                             : std::numeric_limits<double>::infinity();
        if (!(condition <= options_.max_condition)) {  // regular at the predictor, not at the solution
          --rep.steps;
          rep.status = FlowStatus::Singular;
          rep.failed_step = first_node + k;
          rep.message = "step n=" + std::to_string(first_node + k) + ": " +
                        singular_step_reason(condition, options_.max_condition);
          return out;
        }
        if (record && seed) out.memo.push_back({dz, chord});
        if constexpr (d == 0) {
          if (affine_ && !mapped) {
            z_c = flat_interval_coordinates(z).template tail<nz>() - dz * flat_interval_coordinates(s);
            if (!carry.valid) {  // interval 1's derivatives (the carry holds them after step 1)
              carry.interval = flat_interval_derivatives<Sch>(model_, z, h_);
              carry.valid = true;
            }
            affine_gradient.reference = carry.interval;
            affine_gradient.at = flat_interval_coordinates(z);
            mapped = true;
          }
        }
      }
      // Which prediction the solution lay closer to, decided once the step is solved: a taken
      // step is known only after its confirmation (a refused one was solved again from there).
      if (guided) {
        const Vec<double, nz> solved = unknowns_relative_to(z, s);
        const Vec<double, nz> other = extrapolated ? predicted : unknowns_relative_to(s, s);
        guide_closer = (solved - from_guide).template lpNorm<Eigen::Infinity>() <=
                       (solved - other).template lpNorm<Eigen::Infinity>();
      }
      if (seed) {
        const Eigen::MatrixXd& S = out.sensitivity;
        next.resize(S.rows(), S.cols());
        // Column by column (each seed's column is contiguous): fixed-size products, vectorized;
        // at these sizes GEMM's packing costs more than the product.
        const double h = h_;
        for (Eigen::Index j = 0; j < S.cols(); ++j) {
          const Eigen::Map<const Vec<double, ns>> sj(S.col(j).data());
          Eigen::Map<Vec<double, ns>> nj(next.col(j).data());
          // The base node of interval n is the end of interval n-1.
          nj.template segment<r>(Sch::x_off) = sj.template segment<r>(Sch::x_off) +
                                               h * sj.template segment<r>(Sch::v_off) +
                                               (h * h) * sj.template segment<r>(Sch::X2_off);
          nj.template segment<r>(Sch::v_off) = sj.template segment<r>(Sch::v_off) + h * sj.template segment<r>(Sch::V1_off);
          nj.template segment<d>(Sch::Om_off) = sj.template segment<d>(Sch::Om_off) + h * sj.template segment<d>(Sch::O1_off);
          // dz sj as a sum of dz's columns: vectorized down each column (Eigen's gemv call and its
          // coefficient-wise lazy product were each slower here, beanie Galerkin 6: 21 x 34).
          Vec<double, nz> moved = dz.col(0) * sj(0);
          for (int c = 1; c < ns; ++c) moved.noalias() += dz.col(c) * sj(c);
          nj.template segment<nz>(Sch::X2_off) = moved;
        }
        if constexpr (d > 0) {
          if (with_group)  // g_n = g_{n-1} W_{n-1}:  δg_n = Ad_{W^{-1}} δg_{n-1} + h δW
            next.bottomRows(d) = G::Ad(G::inverse(s.W)) * S.bottomRows(d) + h * S.middleRows(Sch::W_off, d);
        }
        out.sensitivity.swap(next);
      }
      out.g_last = G::compose(out.g_last, s.W);
      if constexpr (d > 0) {  // the extrapolation's intervals
        earlier = before;
        before = s;
      }
      s = z;
      if (keep)
        ivs.push_back(z);
      else
        ivs.back() = z;
    }
    return out;
  }

 private:
  // Affine steps (d = 0): every interval's Hessian is the same matrix (degree.hpp), so one
  // evaluation, at the start interval, gives the carry (the state's part of step 1's equations)
  // and step 1's matrix, factored, its condition and its sensitivity, as galerkin_step_sensitivity
  // gives them at step 1's solution from two more (electron Galerkin 4: three interval Hessians
  // in nested duals, ~13 µs, were a 200-step flow's first step). Step 1 is then solved by chord
  // steps on its exact matrix. False (nothing to reuse) when the matrix is too ill-conditioned:
  // step 1 then evaluates its own and reports it.
  bool affine_start(const Interval<Sch, double>& start, StepCarry<Sch>& carry, ChordMatrix<Sch::unknowns>& chord,
                    Eigen::Matrix<double, Sch::unknowns, Sch::state>& dz, double& condition) const {
    constexpr int nz = Sch::unknowns, ns = Sch::state;
    carry.interval = flat_interval_derivatives<Sch>(model_, start, h_);
    carry.valid = true;
    Eigen::Matrix<double, nz, nz + ns> J;
    flat_step_jacobian<Sch, nz + ns>(FlatStepMaps<Sch>(h_), h_, carry.interval.hessian, &carry.interval.hessian, J);
    dz = implicit_sensitivity<nz, ns>(J, &chord, &condition);
    if (condition <= options_.max_condition) return true;
    chord.valid = false;
    return false;
  }

  // The next interval's unknowns (solve_galerkin_step's predictor layout) extrapolated in n from
  // intervals a0 = n-3 (if given: quadratic; else linear), a = n-2 and b = n-1; W_n as
  // W_{n-1} D with log D extrapolated from the last increments D_k = W_{k-1}^{-1} W_k.
  Vec<double, Sch::unknowns> extrapolate(const Interval<Sch, double>* a0, const Interval<Sch, double>& a,
                                         const Interval<Sch, double>& b) const {
    constexpr int r = Sch::r, d = Sch::d;
    auto ext = [&](const auto& xa0, const auto& xa, const auto& xb) {
      using V = std::decay_t<decltype(xb)>;
      return a0 ? V(3 * xb - 3 * xa + xa0) : V(2 * xb - xa);
    };
    const Interval<Sch, double>& c = a0 ? *a0 : a;
    Vec<double, Sch::unknowns> p;
    p.template segment<r>(0) = ext(c.X2, a.X2, b.X2);
    p.template segment<r>(r) = ext(c.V1, a.V1, b.V1);
    if constexpr (d > 0) {
      p.template segment<d>(2 * r) = ext(c.O1, a.O1, b.O1);
      const typename G::template Tangent<double> last = G::log(G::compose(G::inverse(a.W), b.W));
      p.template segment<d>(2 * r + d) = (a0 ? 2 * last - G::log(G::compose(G::inverse(a0->W), a.W)) : last) / h_;
    }
    p.template tail<Sch::aux>() = ext(c.w, a.w, b.w);
    return p;
  }

  // Interval z's unknowns in solve_galerkin_step's predictor layout, ζ relative to interval s's W
  // (W_z = W_s exp(h ζ)).
  Vec<double, Sch::unknowns> unknowns_relative_to(const Interval<Sch, double>& z, const Interval<Sch, double>& s) const {
    constexpr int r = Sch::r, d = Sch::d;
    Vec<double, Sch::unknowns> p;
    p.template segment<r>(0) = z.X2;
    p.template segment<r>(r) = z.V1;
    if constexpr (d > 0) {
      p.template segment<d>(2 * r) = z.O1;
      p.template segment<d>(2 * r + d) = G::log(G::compose(G::inverse(s.W), z.W)) / h_;
    }
    p.template tail<Sch::aux>() = z.w;
    return p;
  }

  Model model_;
  double h_;
  NewtonOptions options_;
  bool affine_;
};

// Moves an interval along its tangent coordinates (Galerkin offsets; W <- W exp(h δ)).
template <class Sch>
Interval<Sch, double> retract(const Interval<Sch, double>& s, const Vec<double, Sch::state>& delta, double h) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d;
  Interval<Sch, double> o = s;
  o.x += delta.template segment<r>(Sch::x_off);
  o.v += delta.template segment<r>(Sch::v_off);
  o.Om += delta.template segment<d>(Sch::Om_off);
  o.X2 += delta.template segment<r>(Sch::X2_off);
  o.V1 += delta.template segment<r>(Sch::V1_off);
  o.O1 += delta.template segment<d>(Sch::O1_off);
  if constexpr (d > 0) {
    const typename G::template Tangent<double> step = h * delta.template segment<d>(Sch::W_off);
    o.W = G::compose(o.W, G::template exp<double>(step));
  }
  o.w += delta.template segment<Sch::aux>(Sch::aux_off);
  return o;
}

// The δ with retract(b, δ, h) = a.
template <class Sch>
Vec<double, Sch::state> state_difference(const Interval<Sch, double>& a, const Interval<Sch, double>& b, double h) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d;
  Vec<double, Sch::state> delta;
  delta.template segment<r>(Sch::x_off) = a.x - b.x;
  delta.template segment<r>(Sch::v_off) = a.v - b.v;
  delta.template segment<d>(Sch::Om_off) = a.Om - b.Om;
  delta.template segment<r>(Sch::X2_off) = a.X2 - b.X2;
  delta.template segment<r>(Sch::V1_off) = a.V1 - b.V1;
  delta.template segment<d>(Sch::O1_off) = a.O1 - b.O1;
  if constexpr (d > 0) delta.template segment<d>(Sch::W_off) = G::log(G::compose(G::inverse(b.W), a.W)) / h;
  delta.template segment<Sch::aux>(Sch::aux_off) = a.w - b.w;
  return delta;
}

// M_n = μ^R_{W_n}(L~_n) = d/dε L~_n(exp(ε ζ) W_n): the body momentum at node n (n = 0..N-1).
template <class Sch>
Vec<double, Sch::d> galerkin_body_momentum(const typename Sch::Model& model, const Interval<Sch, double>& iv, double h) {
  using G = typename Sch::Group;
  constexpr int d = Sch::d;
  using T = Dual<double, d>;
  Interval<Sch, T> q = iv.template cast<T>();
  typename G::template Tangent<T> eps;
  for (int a = 0; a < d; ++a) eps(a) = T::variable(0.0, a);
  q.W = G::compose(G::template exp<T>(eps), q.W);
  const T L = interval_action(model, q, h);
  Vec<double, d> M;
  for (int a = 0; a < d; ++a) M(a) = L.d[a];
  return M;
}

// J_n = Ad*_{g_n^{-1}} M_n for n = 0 .. N-1: constant along every discrete solution (L~_n depends
// on g only through W_n = g_n^{-1} g_{n+1}).
template <class Sch>
std::vector<Vec<double, Sch::d>> galerkin_spatial_momentum(const typename Sch::Model& model,
                                                           const GalerkinTrajectory<Sch>& tr) {
  using G = typename Sch::Group;
  const auto g = tr.group();
  std::vector<Vec<double, Sch::d>> J;
  J.reserve(tr.intervals.size());
  for (int n = 0; n < tr.N(); ++n)
    J.push_back(G::Ad(G::inverse(g[n])).transpose() * galerkin_body_momentum(model, tr.intervals[n], tr.h));
  return J;
}

// The momentum conjugate to the node velocity, π_v = ∂L~/∂v_n (from interval n-1; at node 0,
// -∂L~_0/∂v_0): the Galerkin scheme's discrete Legendre transform, which approximates ∂ℓ/∂p'' at
// the node to the scheme's order.
template <class Sch>
Vec<double, Sch::r> node_velocity_momentum(const typename Sch::Model& model, const GalerkinTrajectory<Sch>& tr, int n) {
  constexpr int r = Sch::r;
  if (n == 0) return -node_residual<Sch, double>(model, nullptr, &tr.intervals[0], tr.h).template segment<r>(r);
  return node_residual<Sch, double>(model, &tr.intervals[n - 1], nullptr, tr.h).template segment<r>(r);
}

// Where node_jet's p'' comes from.
enum class NodeJetSource {
  LegendreTransform,  // ∂ℓ/∂p'' = π_v solved for p''
  NodeDifferences,    // p'' = v' from the node velocities (node_derivative)
};

// The time derivative at node n of a node quantity f(j) (v or Ω), by differentiating the
// polynomial through K = min(order + 1, N + 1) consecutive nodes around n (one-sided near the
// ends). The scheme's node values carry an error smooth in t of order h^order (METHOD.md §9), so
// the derivative keeps that order.
template <class Sch, class F>
auto node_derivative(const GalerkinTrajectory<Sch>& tr, int n, const F& f) {
  const int N = tr.N(), K = std::min(Sch::order + 1, N + 1);
  const int first = std::clamp(n - K / 2, 0, N + 1 - K);
  auto out = f(n);
  out.setZero();
  // Lagrange basis j at nodes first..first+K-1 (unit spacing), differentiated at n:
  // L_j'(n) = Σ_{m≠j} 1/(j - m) Π_{l≠j,m} (n - l)/(j - l).
  for (int j = first; j < first + K; ++j) {
    double w = 0;
    for (int m = first; m < first + K; ++m) {
      if (m == j) continue;
      double term = 1.0 / (j - m);
      for (int l = first; l < first + K; ++l)
        if (l != j && l != m) term *= static_cast<double>(n - l) / (j - l);
      w += term;
    }
    out += (w / tr.h) * f(j);
  }
  return out;
}

// Whether π_v = ∂L~/∂v_n determines p'' at a node through ℓ alone: the discrete Legendre
// transform approximates ∂(ℓ + λ · χ)/∂p'', and Ω' is not known at the node before p''. So it
// needs ∂χ/∂p'' = 0 and ∂²ℓ/∂p''∂Ω' = 0 (checked at q; automatic derivatives give exact zeros
// for terms that are absent).
template <class C>
bool legendre_transform_applies(const C& model, const Jet<C, double>& q) {
  constexpr int r = C::shape_dim, d = C::Group::dim, m = C::num_constraints;
  using T1 = Dual<double, r + d>;
  using T2 = Dual<T1, r>;
  Jet<C, T2> qt;
  qt.p = q.p.template cast<T2>(), qt.dp = q.dp.template cast<T2>(), qt.Omega = q.Omega.template cast<T2>();
  for (int a = 0; a < r; ++a) {
    qt.ddp(a) = T2(T1::variable(q.ddp(a), a));
    qt.ddp(a).d[a] = T1(1.0);
  }
  for (int a = 0; a < d; ++a) qt.dOmega(a) = T2(T1::variable(q.dOmega(a), r + a));
  const T2 l = model.template lagrangian<T2>(qt);
  for (int a = 0; a < r; ++a)
    for (int b = 0; b < d; ++b)
      if (l.d[a].d[r + b] != 0.0) return false;
  if constexpr (m > 0) {
    const Vec<T2, m> chi = model_constraints(model, qt);
    for (int c = 0; c < m; ++c)
      for (int a = 0; a < r; ++a)
        if (chi(c).d[a].v != 0.0) return false;
  }
  return true;
}

// The jet at node n. p, p' and Ω are the node's; Ω' is node_derivative of Ω. p'' solves the
// inverse Legendre transform ∂ℓ/∂p''(x_n, v_n, p'', Ω_n, Ω'_n) = π_v (Newton; ℓ strictly convex in
// p'', the regularity of a higher-order Lagrangian) where `source` asks for it and
// legendre_transform_applies; otherwise it is node_derivative of v. Both are of the scheme's
// order. `source`: in, the preferred source; out, the one used. False if Newton does not
// converge or the jet is not finite.
template <class Sch>
bool node_jet(const typename Sch::Model& model, const GalerkinTrajectory<Sch>& tr, int n, Jet<typename Sch::Model, double>& q,
              NodeJetSource& source) {
  using C = typename Sch::Model;
  constexpr int r = Sch::r;
  q.p = tr.x(n);
  q.dp = tr.v(n);
  q.Omega = tr.Omega(n);
  q.ddp = node_derivative(tr, n, [&](int j) { return tr.v(j); });
  if constexpr (Sch::d > 0) q.dOmega = node_derivative(tr, n, [&](int j) { return tr.Omega(j); });
  if (source == NodeJetSource::NodeDifferences || !legendre_transform_applies(model, q)) {
    source = NodeJetSource::NodeDifferences;
    return q.ddp.allFinite() && q.dOmega.allFinite();
  }
  const Vec<double, r> pi = node_velocity_momentum(model, tr, n);
  using T1 = Dual<double, r>;
  using T2 = Dual<T1, r>;
  for (int it = 0; it < 20; ++it) {
    Jet<C, T2> qt;
    qt.p = q.p.template cast<T2>(), qt.dp = q.dp.template cast<T2>();
    qt.Omega = q.Omega.template cast<T2>(), qt.dOmega = q.dOmega.template cast<T2>();
    for (int a = 0; a < r; ++a) qt.ddp(a) = T2(T1::variable(q.ddp(a), a));
    for (int a = 0; a < r; ++a) qt.ddp(a).d[a] = T1(1.0);
    const T2 l = model.template lagrangian<T2>(qt);
    Vec<double, r> g;
    Eigen::Matrix<double, r, r> H;
    for (int a = 0; a < r; ++a) {
      g(a) = l.d[a].v - pi(a);
      for (int b = 0; b < r; ++b) H(a, b) = l.d[a].d[b];
    }
    const Vec<double, r> step = H.partialPivLu().solve(-g);
    if (!step.allFinite()) return false;
    q.ddp += step;
    if (step.template lpNorm<Eigen::Infinity>() <= 1e-14 * (1.0 + q.ddp.template lpNorm<Eigen::Infinity>())) return true;
  }
  return false;
}

template <class Sch>
bool node_jet(const typename Sch::Model& model, const GalerkinTrajectory<Sch>& tr, int n, Jet<typename Sch::Model, double>& q) {
  NodeJetSource source = NodeJetSource::LegendreTransform;
  return node_jet(model, tr, n, q, source);
}

// The jets at nodes 0..N from one source for all: the Legendre transform where it applies and
// converges at every node, else node differences at every node. False if a jet is not finite.
template <class Sch>
bool node_jets(const typename Sch::Model& model, const GalerkinTrajectory<Sch>& tr, std::vector<Jet<typename Sch::Model, double>>& q,
               NodeJetSource& source) {
  q.assign(tr.N() + 1, {});
  source = NodeJetSource::LegendreTransform;
  for (int n = 0; n <= tr.N(); ++n) {
    NodeJetSource used = source;
    if (!node_jet(model, tr, n, q[n], used) || used != source) {
      if (source == NodeJetSource::NodeDifferences) return false;
      source = NodeJetSource::NodeDifferences;
      n = -1;  // again from node 0, by node differences
    }
  }
  return true;
}

}  // namespace lpshoot
