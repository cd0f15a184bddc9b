// One step of a Galerkin flow (METHOD.md §9): from interval n-1 (the flow's state: base node
// n-1 and its increments, group increment and local variables) to interval n.
//
// Unknowns z = (X2, V1, O1, ζ, bubbles, multipliers) of interval n, with W_n = Ŵ exp(h ζ) around
// the current iterate (re-centred after every update: derivatives at ζ = 0). Equations: the
// node-n equations E_n (node_residual of intervals n-1 and n) and interval n's own equations
// (bubbles: ∂L~/∂a = 0; constraints at the Gauss points). Interval n's base is interval n-1's
// end. Everything is scaled to O(1) (galerkin.hpp), so the Newton tolerance is relative.
#pragma once

#include "galerkin.hpp"
#include "galerkin_flat.hpp"
#include "galerkin_group.hpp"
#include "galerkin_group_gradient.hpp"
#include "newton.hpp"

namespace lpshoot {

// Interval n's base node from the state, in scalar T, with the unknowns of `z` (its base unused).
// With T a Dual: unknown i (< z_seeded) is seeded in column i and, if seed_state, the state's
// tangent coordinate j (Galerkin offsets, < state_seeded) in column state_col + j; the others
// (the multipliers, which enter linearly) stay constants.
template <class Sch, class T>
void galerkin_step_block(const Interval<Sch, double>& state, const Interval<Sch, double>& z, bool seed_state,
                         double h, Interval<Sch, T>& left, Interval<Sch, T>& right, int z_seeded = Sch::unknowns,
                         int state_col = Sch::unknowns, int state_seeded = Sch::state) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d, na = Sch::aux;
  auto var = [](double x, int col, int limit, int first) {
    if constexpr (std::is_same_v<T, double>) {
      (void)col, (void)limit, (void)first;
      return x;
    } else {
      return col < limit ? T::variable(x, first + col) : T(x);
    }
  };
  const int sc = state_col, sl = state_seeded;
  left = state.template cast<T>();
  if (seed_state) {
    for (int a = 0; a < r; ++a) {
      left.x(a) = var(state.x(a), Sch::x_off + a, sl, sc);
      left.v(a) = var(state.v(a), Sch::v_off + a, sl, sc);
      left.X2(a) = var(state.X2(a), Sch::X2_off + a, sl, sc);
      left.V1(a) = var(state.V1(a), Sch::V1_off + a, sl, sc);
    }
    for (int a = 0; a < d; ++a) {
      left.Om(a) = var(state.Om(a), Sch::Om_off + a, sl, sc);
      left.O1(a) = var(state.O1(a), Sch::O1_off + a, sl, sc);
    }
    if constexpr (d > 0) {
      typename G::template Tangent<T> delta;
      for (int a = 0; a < d; ++a) delta(a) = var(0.0, Sch::W_off + a, sl, sc) * h;  // W exp(h δ)
      left.W = G::compose(left.W, G::template exp<T>(delta));
    }
    for (int a = 0; a < na; ++a) left.w(a) = var(state.w(a), Sch::aux_off + a, sl, sc);
  }
  right = z.template cast<T>();
  const Interval<Sch, T> base = next_interval_base(left, h);
  right.x = base.x, right.v = base.v, right.Om = base.Om;
  const int zl = z_seeded;
  for (int a = 0; a < r; ++a) {
    right.X2(a) = var(z.X2(a), a, zl, 0);
    right.V1(a) = var(z.V1(a), r + a, zl, 0);
  }
  for (int a = 0; a < d; ++a) right.O1(a) = var(z.O1(a), 2 * r + a, zl, 0);
  if constexpr (d > 0) {
    typename G::template Tangent<T> zeta;
    for (int a = 0; a < d; ++a) zeta(a) = var(0.0, 2 * r + d + a, zl, 0) * h;  // Ŵ exp(h ζ)
    right.W = G::compose(right.W, G::template exp<T>(zeta));
  }
  for (int a = 0; a < na; ++a) right.w(a) = var(z.w(a), 2 * r + 2 * d + a, zl, 0);
}

// F = (E_n, interval n's equations) at z and its derivatives: columns are the unknowns, then (if
// NO = unknowns + state) the state's tangent coordinates. Given `fixed` (interval n-1's part of
// E_n, which does not depend on z) only interval n is differentiated.
//
// Derivatives are taken only in the directions each part depends on (nested duals are costly in
// the product of their widths):
// - L~ = L0 + λ · C is linear in the multipliers (galerkin.hpp), the last Q m unknowns and state
//   coordinates: second derivatives by nested duals over the other ("smooth") directions only;
//   the multiplier columns are first derivatives of C (∂E/∂λ = ∂C/∂e / h; the multiplier rows
//   C/h do not depend on λ).
// - Interval n depends on the state only through its base node (x, v, Ω at the end of interval
//   n-1, linear in the state): it is differentiated in its smooth unknowns and its base node, and
//   the base columns are mapped to the state's by that linear map.
// - Interval n-1 (the state) enters E_n only: differentiated in its own smooth coordinates.
template <class Sch, int NO>
void evaluate_galerkin_step_nested(const typename Sch::Model& model, double h, const Interval<Sch, double>& state,
                                   const Interval<Sch, double>& z, bool with_state,
                                   const Vec<double, Sch::variation>* fixed, Vec<double, Sch::unknowns>& F,
                                   Eigen::Matrix<double, Sch::unknowns, NO>& J) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d, nv = Sch::variation, na = Sch::aux, nz = Sch::unknowns, ns = Sch::state;
  constexpr int node = Sch::node, nm = multiplier_count<Sch>, nzs = nz - nm, nss = ns - nm, nb = na - nm;
  static_assert(NO == nz || NO == nz + ns, "columns: the unknowns, or the unknowns and the state");
  constexpr bool state_cols = NO == nz + ns;
  const bool left_seeded = state_cols && with_state && !fixed;

  // Interval n: smooth unknowns in columns 0..nzs-1, its base node (x, v, Ω) in nzs..nzs+node-1.
  constexpr int NR = state_cols ? nzs + node : nzs;
  using TR = Dual<double, NR>;
  Interval<Sch, TR> right = z.template cast<TR>();
  const Interval<Sch, double> base = next_interval_base(state, h);
  right.x = base.x.template cast<TR>(), right.v = base.v.template cast<TR>(), right.Om = base.Om.template cast<TR>();
  for (int a = 0; a < r; ++a) {
    right.X2(a) = TR::variable(z.X2(a), a);
    right.V1(a) = TR::variable(z.V1(a), r + a);
    if constexpr (state_cols) {
      right.x(a) = TR::variable(base.x(a), nzs + a);
      right.v(a) = TR::variable(base.v(a), nzs + r + a);
    }
  }
  for (int a = 0; a < d; ++a) {
    right.O1(a) = TR::variable(z.O1(a), 2 * r + a);
    if constexpr (state_cols) right.Om(a) = TR::variable(base.Om(a), nzs + 2 * r + a);
  }
  if constexpr (d > 0) {
    typename G::template Tangent<TR> zeta;
    for (int a = 0; a < d; ++a) zeta(a) = TR::variable(0.0, 2 * r + d + a) * h;  // Ŵ exp(h ζ)
    right.W = G::compose(right.W, G::template exp<TR>(zeta));
  }
  for (int a = 0; a < nb; ++a) right.w(a) = TR::variable(z.w(a), 2 * r + 2 * d + a);
  const Vec<TR, nv> E = node_residual<Sch, TR>(model, nullptr, &right, h);
  const Vec<TR, na> A = aux_residual<Sch, TR>(model, right, h);

  J.setZero();
  Eigen::Matrix<double, nz, node> Jbase;
  for (int i = 0; i < nz; ++i) {
    const TR& f = i < nv ? E(i) : A(i - nv);
    F(i) = f.v;
    for (int c = 0; c < nzs; ++c) J(i, c) = f.d[c];
    if constexpr (state_cols)
      for (int c = 0; c < node; ++c) Jbase(i, c) = f.d[nzs + c];
  }
  if constexpr (state_cols) {  // base = (x + h v + h² X2, v + h V1, Ω + h O1) of the state
    for (int a = 0; a < r; ++a) {
      J.col(nz + Sch::x_off + a) += Jbase.col(a);
      J.col(nz + Sch::v_off + a) += h * Jbase.col(a) + Jbase.col(r + a);
      J.col(nz + Sch::X2_off + a) += (h * h) * Jbase.col(a);
      J.col(nz + Sch::V1_off + a) += h * Jbase.col(r + a);
    }
    for (int a = 0; a < d; ++a) {
      J.col(nz + Sch::Om_off + a) += Jbase.col(2 * r + a);
      J.col(nz + Sch::O1_off + a) += h * Jbase.col(2 * r + a);
    }
  }

  // Interval n-1's part of E_n.
  if (fixed) {
    F.template head<nv>() += *fixed;
  } else if (left_seeded) {
    if constexpr (state_cols) {
      using TL = Dual<double, nss>;
      const Interval<Sch, TL> left = seeded_state<Sch, TL>(state, h, 0);
      const Vec<TL, nv> El = node_residual<Sch, TL>(model, &left, nullptr, h);
      for (int i = 0; i < nv; ++i) {
        F(i) += El(i).v;
        for (int c = 0; c < nss; ++c) J(i, nz + c) += El(i).d[c];
      }
    }
  } else {
    F.template head<nv>() += node_residual<Sch, double>(model, &state, nullptr, h);
  }

  if constexpr (nm > 0) {
    Interval<Sch, double> rd = z;
    rd.x = base.x, rd.v = base.v, rd.Om = base.Om;
    J.template block<nv, nm>(0, nzs) = node_multiplier_jacobian<Sch>(model, nullptr, &rd, h);
    if constexpr (nb > 0) J.template block<nb, nm>(nv, nzs) = bubble_multiplier_jacobian<Sch>(model, rd, h);
    if constexpr (state_cols)
      if (left_seeded) J.template block<nv, nm>(0, nz + nss) = node_multiplier_jacobian<Sch>(model, &state, nullptr, h);
  }
}

// Without a group the jet is linear in the intervals' coordinates and the chain rule through it
// is cheaper (galerkin_flat.hpp), for the step matrix alone as well (measured: electron Galerkin
// 4 step 6.7 → 4.5 µs, Galerkin 6 23 → 7.7 µs, bench_galerkin_step). With a group, a step's
// sensitivity comes from each interval's Hessian (galerkin_group.hpp); so does its step matrix
// alone when the interval has bubbles, otherwise nested duals in the unknowns and the node
// perturbations are as cheap (beanie, plain flow per step: Galerkin 4 92 µs from the Hessian
// against 87 µs nested, Galerkin 6 193 against 250 µs; bench_galerkin_step).
template <class Sch, int NO>
void evaluate_galerkin_step(const typename Sch::Model& model, double h, const Interval<Sch, double>& state,
                            const Interval<Sch, double>& z, bool with_state, const Vec<double, Sch::variation>* fixed,
                            Vec<double, Sch::unknowns>& F, Eigen::Matrix<double, Sch::unknowns, NO>& J,
                            StepCarry<Sch>* carry = nullptr) {
  if constexpr (Sch::d == 0) {
    evaluate_galerkin_step_flat<Sch, NO>(model, h, state, z, with_state, fixed, F, J, carry);
  } else if constexpr (NO == Sch::unknowns + Sch::state) {
    if (with_state && !fixed)
      evaluate_galerkin_step_group<Sch, NO>(model, h, state, z, nullptr, F, J, carry);
    else
      evaluate_galerkin_step_nested<Sch, NO>(model, h, state, z, with_state, fixed, F, J);
  } else if (fixed && Sch::bubbles > 0) {
    evaluate_galerkin_step_group<Sch, NO>(model, h, state, z, fixed, F, J, nullptr);
  } else {
    (void)carry;
    evaluate_galerkin_step_nested<Sch, NO>(model, h, state, z, with_state, fixed, F, J);
  }
}

// F at z given the state's part of E_n (`fixed`).
template <class Sch>
Vec<double, Sch::unknowns> galerkin_step_residual(const typename Sch::Model& model, double h,
                                                  const Interval<Sch, double>& state, const Interval<Sch, double>& z,
                                                  const Vec<double, Sch::variation>& fixed) {
  constexpr int nv = Sch::variation, na = Sch::aux;
  Interval<Sch, double> left, right;
  galerkin_step_block(state, z, false, h, left, right);
  Vec<double, Sch::unknowns> F;
  if constexpr (Sch::d == 0) {  // the chain rule through the jet (galerkin_flat.hpp): first derivatives only
    const Vec<double, IntervalDerivatives<Sch>::ne> g = flat_interval_gradient<Sch>(model, right, h);
    F = flat_right_rows<Sch>(g, h);
    F.template head<nv>() += fixed;
  } else if constexpr (chains_interval_derivatives<Sch>) {  // (∂L~/∂y, C) by the chain rule, mapped to the rows
    using G = typename Sch::Group;
    const Vec<double, IntervalDerivatives<Sch>::ne> g = group_interval_gradient_chained<Sch>(model, right, h);
    F.noalias() = (1.0 / h) * group_right_map_times<Sch, 1>(h, G::Ad(G::inverse(right.W)), g);
    F.template head<nv>() += fixed;
  } else {
    Vec<double, nv> E;
    Vec<double, na> R;
    right_interval_rows<Sch>(model, right, h, E, R);
    F.template head<nv>() = fixed + E;
    F.template tail<na>() = R;
  }
  return F;
}

// z <- z ⊕ dz (unknowns' layout).
template <class Sch>
void apply_galerkin_correction(Interval<Sch, double>& z, const Vec<double, Sch::unknowns>& dz, double h) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d;
  z.X2 += dz.template segment<r>(0);
  z.V1 += dz.template segment<r>(r);
  z.O1 += dz.template segment<d>(2 * r);
  if constexpr (d > 0) {
    const typename G::template Tangent<double> step = h * dz.template segment<d>(2 * r + d);
    z.W = G::compose(z.W, G::template exp<double>(step));
  }
  z.w += dz.template tail<Sch::aux>();
}

// |z_i| of the unknowns, for Newton's relative tolerance (0 for ζ: W's own size has no scale).
template <class Sch>
Vec<double, Sch::unknowns> unknowns_magnitude(const Interval<Sch, double>& z) {
  constexpr int r = Sch::r, d = Sch::d;
  Vec<double, Sch::unknowns> scale = Vec<double, Sch::unknowns>::Zero();
  scale.template segment<r>(0) = z.X2.cwiseAbs();
  scale.template segment<r>(r) = z.V1.cwiseAbs();
  scale.template segment<d>(2 * r) = z.O1.cwiseAbs();
  scale.template tail<Sch::aux>() = z.w.cwiseAbs();
  return scale;
}

// Interval n's first iterate: interval n-1's unknowns on interval n's base node, or
// `predictor` (unknowns' layout, ζ: W = W_{n-1} exp(h ζ)).
template <class Sch>
Interval<Sch, double> galerkin_step_start(const Interval<Sch, double>& state, double h,
                                          const Vec<double, Sch::unknowns>* predictor) {
  constexpr int r = Sch::r, d = Sch::d;
  Interval<Sch, double> z = state;
  const Interval<Sch, double> base = next_interval_base(state, h);
  z.x = base.x, z.v = base.v, z.Om = base.Om;
  if (predictor) {
    z.X2 = predictor->template segment<r>(0);
    z.V1 = predictor->template segment<r>(r);
    if constexpr (d > 0) {
      using G = typename Sch::Group;
      z.O1 = predictor->template segment<d>(2 * r);
      const typename G::template Tangent<double> step = h * predictor->template segment<d>(2 * r + d);
      z.W = G::compose(state.W, G::template exp<double>(step));
    }
    z.w = predictor->template tail<Sch::aux>();
  }
  return z;
}

// max_i |dz_i| / (1 + |z_i|): a correction's size in the units of Newton's test.
template <class Sch>
double relative_size(const Vec<double, Sch::unknowns>& dz, const Interval<Sch, double>& z) {
  return (dz.cwiseAbs().array() / (1.0 + unknowns_magnitude<Sch>(z).array())).maxCoeff();
}

// Solves step n (interval n from interval n-1 = `state`) by Newton from the predictor "interval
// n-1's unknowns", or `predictor` (unknowns' layout, ζ: W = W_{n-1} exp(h ζ)); on return z is
// interval n (its base node included).
// `chord`: a flow's factored step matrix, for chord iterations (newton_solve).
// `carry`: the state's derivatives, when the flow has them (its part of E_n is read off them);
// left for galerkin_step_sensitivity to move on to interval n. An affine flow's steps after the
// first: solve_mapped_affine_step (galerkin_affine.hpp).
template <class Sch>
StepReport solve_galerkin_step(const typename Sch::Model& model, double h, const Interval<Sch, double>& state, int n,
                               const NewtonOptions& opt, Interval<Sch, double>& z,
                               ChordMatrix<Sch::unknowns>* chord = nullptr, StepCarry<Sch>* carry = nullptr,
                               const Vec<double, Sch::unknowns>* predictor = nullptr) {
  constexpr int nz = Sch::unknowns, nv = Sch::variation;
  z = galerkin_step_start<Sch>(state, h, predictor);
  Vec<double, nv> fixed;
  if constexpr (Sch::d == 0) {
    fixed = flat_left_rows<Sch>(carry && carry->valid ? carry->interval.gradient
                                                      : flat_interval_gradient<Sch>(model, state, h),
                                h);
  } else {
    fixed = carry && carry->valid ? group_left_rows<Sch>(carry->interval.gradient, h)
                                  : node_residual<Sch, double>(model, &state, nullptr, h);
  }
  if (!all_finite(fixed.data(), nv)) return non_finite_step(StepReport(), n);
  return newton_solve<nz>(
      n, opt,
      [&](Vec<double, nz>& F, Eigen::Matrix<double, nz, nz>& J) {
        evaluate_galerkin_step<Sch, nz>(model, h, state, z, false, &fixed, F, J);
      },
      [&](Vec<double, nz>& F) { F = galerkin_step_residual<Sch>(model, h, state, z, fixed); },
      [&](const Vec<double, nz>& dz) { apply_galerkin_correction<Sch>(z, dz, h); },
      [&] { return unknowns_magnitude<Sch>(z); }, chord);
}

// Confirms a step that newton_solve ended on a prediction (StepReport::predicted), from the
// evaluation at z its sensitivity made (F there and the exact step matrix, factored): the exact
// Newton correction at z must be within predicted_step_allowance tolerances (newton.hpp), plus
// the residual's noise as newton_solve allows at a stall. It is then applied (its error is O(correction²), below the
// chord step's that it replaces) and interval n's carried gradient is moved with it to first
// order: its Hessian times the correction and, with a group, (h/2) Bᵀ ζ from re-centring δ at
// W exp(h ζ) (Baker–Campbell–Hausdorff, as galerkin_group.hpp's bracket terms). The next
// step's E_n sees the corrected interval; the Hessian and the sensitivity stay those at z, off
// by the correction, relatively. False: nothing is changed and the caller solves again from z.
template <class Sch>
bool confirm_predicted_step(double h, const NewtonOptions& opt, const Vec<double, Sch::unknowns>& F,
                            const ChordMatrix<Sch::unknowns>& factored, Interval<Sch, double>& z, StepCarry<Sch>* carry) {
  constexpr int r = Sch::r, d = Sch::d, nz = Sch::unknowns, ne = IntervalDerivatives<Sch>::ne;
  static_assert(ne - Sch::X2_off == nz, "the unknowns are interval n's coordinates from X2 on");
  const Vec<double, nz> correction = factored.lu.solve(-F);
  const Vec<double, nz> scale = unknowns_magnitude<Sch>(z);
  if (!all_finite(correction.data(), nz) ||
      !((correction.cwiseAbs().array() - predicted_step_bound(opt, factored.condition) * (1.0 + scale.array())) <= 0.0)
           .all())
    return false;
  apply_galerkin_correction<Sch>(z, correction, h);
  if (carry && carry->valid) {
    Vec<double, ne> moved = carry->interval.hessian.template rightCols<nz>() * correction;
    if constexpr (d > 0) {
      const Eigen::Matrix<double, d, d> B =
          bracket_form<typename Sch::Group>(carry->interval.gradient.template segment<d>(Sch::W_off));
      moved.template segment<d>(Sch::W_off) += (0.5 * h) * (B.transpose() * correction.template segment<d>(2 * r + d));
    }
    carry->interval.gradient += moved;
  }
  return true;
}

// dz/d(state) at a solved step (nz x ns), by the implicit function theorem. Optionally the step
// matrix ∂F/∂z there, factored (for the next step's chord iterations), and its 1-norm condition
// number (the regularity check at the solution). `carry`: a flow's derivatives of the state from the step
// before, updated to this step's (galerkin_flat.hpp). `residual`: F at z, from the same evaluation.
template <class Sch>
Eigen::Matrix<double, Sch::unknowns, Sch::state> galerkin_step_sensitivity(
    const typename Sch::Model& model, double h, const Interval<Sch, double>& state, const Interval<Sch, double>& z,
    ChordMatrix<Sch::unknowns>* chord = nullptr, double* condition = nullptr, StepCarry<Sch>* carry = nullptr,
    Vec<double, Sch::unknowns>* residual = nullptr) {
  constexpr int nz = Sch::unknowns, ns = Sch::state;
  Vec<double, nz> F;
  Eigen::Matrix<double, nz, nz + ns> J;
  evaluate_galerkin_step<Sch, nz + ns>(model, h, state, z, true, nullptr, F, J, carry);
  if (residual) *residual = F;
  return implicit_sensitivity<nz, ns>(J, chord, condition);
}

}  // namespace lpshoot
