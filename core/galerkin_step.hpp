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
// With T a Dual: the unknowns are seeded in columns 0..nz-1 and, if seed_state, the state's
// tangent coordinates (Galerkin offsets) in columns nz..nz+ns-1.
template <class Sch, class T>
void galerkin_step_block(const Interval<Sch, double>& state, const Interval<Sch, double>& z, bool seed_state,
                         double h, Interval<Sch, T>& left, Interval<Sch, T>& right) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d, na = Sch::aux, nz = Sch::unknowns;
  auto var = [](double x, int col) {
    if constexpr (std::is_same_v<T, double>) {
      (void)col;
      return x;
    } else {
      return col < static_cast<int>(T().d.size()) ? T::variable(x, col) : T(x);
    }
  };
  left = state.template cast<T>();
  if (seed_state) {
    const int o = nz;
    for (int a = 0; a < r; ++a) {
      left.x(a) = var(state.x(a), o + Sch::x_off + a);
      left.v(a) = var(state.v(a), o + Sch::v_off + a);
      left.X2(a) = var(state.X2(a), o + Sch::X2_off + a);
      left.V1(a) = var(state.V1(a), o + Sch::V1_off + a);
    }
    for (int a = 0; a < d; ++a) {
      left.Om(a) = var(state.Om(a), o + Sch::Om_off + a);
      left.O1(a) = var(state.O1(a), o + Sch::O1_off + a);
    }
    if constexpr (d > 0) {
      typename G::template Tangent<T> delta;
      for (int a = 0; a < d; ++a) delta(a) = var(0.0, o + Sch::W_off + a) * h;  // W exp(h δ)
      left.W = G::compose(left.W, G::template exp<T>(delta));
    }
    for (int a = 0; a < na; ++a) left.w(a) = var(state.w(a), o + Sch::aux_off + a);
  }
  right = z.template cast<T>();
  const Interval<Sch, T> base = next_interval_base(left, h);
  right.x = base.x, right.v = base.v, right.Om = base.Om;
  for (int a = 0; a < r; ++a) {
    right.X2(a) = var(z.X2(a), a);
    right.V1(a) = var(z.V1(a), r + a);
  }
  for (int a = 0; a < d; ++a) right.O1(a) = var(z.O1(a), 2 * r + a);
  if constexpr (d > 0) {
    typename G::template Tangent<T> zeta;
    for (int a = 0; a < d; ++a) zeta(a) = var(0.0, 2 * r + d + a) * h;  // Ŵ exp(h ζ)
    right.W = G::compose(right.W, G::template exp<T>(zeta));
  }
  for (int a = 0; a < na; ++a) right.w(a) = var(z.w(a), 2 * r + 2 * d + a);
}

// F = (E_n, interval n's equations) at z and its derivatives: columns are the unknowns, then (if
// with_state) the state's tangent coordinates. Given `fixed` (interval n-1's part of E_n, which
// does not depend on z) only interval n is differentiated.
template <class Sch, int NO>
void evaluate_galerkin_step(const typename Sch::Model& model, double h, const Interval<Sch, double>& state,
                            const Interval<Sch, double>& z, bool with_state, const Vec<double, Sch::variation>* fixed,
                            Vec<double, Sch::unknowns>& F, Eigen::Matrix<double, Sch::unknowns, NO>& J) {
  constexpr int nv = Sch::variation, na = Sch::aux;
  using T = Dual<double, NO>;
  Interval<Sch, T> left, right;
  galerkin_step_block(state, z, with_state, h, left, right);
  const Vec<T, nv> E = node_residual<Sch, T>(model, fixed ? nullptr : &left, &right, h);
  const Vec<T, na> A = aux_residual<Sch, T>(model, right, h);
  for (int i = 0; i < nv; ++i) {
    F(i) = E(i).v + (fixed ? (*fixed)(i) : 0.0);
    for (int c = 0; c < NO; ++c) J(i, c) = E(i).d[c];
  }
  for (int i = 0; i < na; ++i) {
    F(nv + i) = A(i).v;
    for (int c = 0; c < NO; ++c) J(nv + i, c) = A(i).d[c];
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
