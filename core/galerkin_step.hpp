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
// L~ = L0 + λ · C is linear in the multipliers (galerkin.hpp), and they are the last Q m unknowns
// and state coordinates. Second derivatives are taken by nested duals over the other ("smooth")
// directions only; the multiplier columns are first derivatives of C (∂E/∂λ = ∂C/∂e / h, the
// multiplier rows C/h do not depend on λ). This cuts the nested width from unknowns + state to
// their smooth parts (beanie, cubic: 33 to 21).
template <class Sch, int NO>
void evaluate_galerkin_step(const typename Sch::Model& model, double h, const Interval<Sch, double>& state,
                            const Interval<Sch, double>& z, bool with_state, const Vec<double, Sch::variation>* fixed,
                            Vec<double, Sch::unknowns>& F, Eigen::Matrix<double, Sch::unknowns, NO>& J) {
  constexpr int nv = Sch::variation, na = Sch::aux, nz = Sch::unknowns, ns = Sch::state;
  constexpr int nm = multiplier_count<Sch>, nzs = nz - nm, nss = ns - nm, nb = na - nm;
  static_assert(NO == nz || NO == nz + ns, "columns: the unknowns, or the unknowns and the state");
  constexpr bool state_cols = NO == nz + ns;
  constexpr int NS = state_cols ? nzs + nss : nzs;  // seeded (smooth) columns
  using T = Dual<double, NS>;
  Interval<Sch, T> left, right;
  galerkin_step_block(state, z, with_state && state_cols, h, left, right, nzs, nzs, nss);
  const Vec<T, nv> E = node_residual<Sch, T>(model, fixed ? nullptr : &left, &right, h);
  const Vec<T, na> A = aux_residual<Sch, T>(model, right, h);
  // Smooth columns back to their places: z's in 0..nzs-1, the state's in nz..nz+nss-1.
  auto put = [&](int row, const T& f) {
    for (int c = 0; c < nzs; ++c) J(row, c) = f.d[c];
    if constexpr (state_cols)
      for (int c = 0; c < nss; ++c) J(row, nz + c) = f.d[nzs + c];
  };
  J.setZero();
  for (int i = 0; i < nv; ++i) {
    F(i) = E(i).v + (fixed ? (*fixed)(i) : 0.0);
    put(i, E(i));
  }
  for (int i = 0; i < na; ++i) {
    F(nv + i) = A(i).v;
    put(nv + i, A(i));
  }
  if constexpr (nm > 0) {
    Interval<Sch, double> l, rd;
    galerkin_step_block(state, z, false, h, l, rd);
    J.template block<nv, nm>(0, nzs) = node_multiplier_jacobian<Sch>(model, nullptr, &rd, h);
    if constexpr (nb > 0) J.template block<nb, nm>(nv, nzs) = bubble_multiplier_jacobian<Sch>(model, rd, h);
    if constexpr (state_cols)
      if (with_state && !fixed) J.template block<nv, nm>(0, nz + nss) = node_multiplier_jacobian<Sch>(model, &state, nullptr, h);
  }
}

template <class Sch>
Vec<double, Sch::unknowns> galerkin_step_residual(const typename Sch::Model& model, double h,
                                                  const Interval<Sch, double>& state, const Interval<Sch, double>& z,
                                                  const Vec<double, Sch::variation>& fixed) {
  constexpr int nv = Sch::variation, na = Sch::aux;
  Interval<Sch, double> left, right;
  galerkin_step_block(state, z, false, h, left, right);
  Vec<double, Sch::unknowns> F;
  F.template head<nv>() = fixed + node_residual<Sch, double>(model, nullptr, &right, h);
  F.template tail<na>() = aux_residual<Sch, double>(model, right, h);
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

// Solves step n (interval n from interval n-1 = `state`) by Newton from the predictor "interval
// n-1's unknowns"; on return z is interval n (its base node included).
template <class Sch>
StepReport solve_galerkin_step(const typename Sch::Model& model, double h, const Interval<Sch, double>& state, int n,
                               const NewtonOptions& opt, Interval<Sch, double>& z) {
  constexpr int r = Sch::r, d = Sch::d, nz = Sch::unknowns, nv = Sch::variation;
  z = state;
  const Interval<Sch, double> base = next_interval_base(state, h);
  z.x = base.x, z.v = base.v, z.Om = base.Om;
  const Vec<double, nv> fixed = node_residual<Sch, double>(model, &state, nullptr, h);
  if (!all_finite(fixed.data(), nv)) {
    StepReport rep;
    rep.step = n;
    rep.status = StepStatus::NonFinite;
    rep.message = "step n=" + std::to_string(n) + ": the step equations evaluated to a non-finite number";
    return rep;
  }
  return newton_solve<nz>(
      n, opt,
      [&](Vec<double, nz>& F, Eigen::Matrix<double, nz, nz>& J) {
        evaluate_galerkin_step<Sch, nz>(model, h, state, z, false, &fixed, F, J);
      },
      [&](Vec<double, nz>& F) { F = galerkin_step_residual<Sch>(model, h, state, z, fixed); },
      [&](const Vec<double, nz>& dz) { apply_galerkin_correction<Sch>(z, dz, h); },
      [&] {
        Vec<double, nz> scale = Vec<double, nz>::Zero();
        scale.template segment<r>(0) = z.X2.cwiseAbs();
        scale.template segment<r>(r) = z.V1.cwiseAbs();
        scale.template segment<d>(2 * r) = z.O1.cwiseAbs();
        scale.template tail<Sch::aux>() = z.w.cwiseAbs();
        return scale;
      });
}

// dz/d(state) at a solved step (nz x ns), by the implicit function theorem.
template <class Sch>
Eigen::Matrix<double, Sch::unknowns, Sch::state> galerkin_step_sensitivity(const typename Sch::Model& model, double h,
                                                                           const Interval<Sch, double>& state,
                                                                           const Interval<Sch, double>& z) {
  constexpr int nz = Sch::unknowns, ns = Sch::state;
  Vec<double, nz> F;
  Eigen::Matrix<double, nz, nz + ns> J;
  evaluate_galerkin_step<Sch, nz + ns>(model, h, state, z, true, nullptr, F, J);
  const Eigen::Matrix<double, nz, nz> Jz = J.template leftCols<nz>();
  const Eigen::Matrix<double, nz, ns> Js = J.template rightCols<ns>();
  return -Jz.partialPivLu().solve(Js);
}

}  // namespace lpshoot
