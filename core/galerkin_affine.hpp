// Affine Galerkin flows without a group (degree.hpp: ℓ quadratic and χ affine in the jet, d = 0):
// the steps after the first, from the step map and the constant interval Hessian.
//
// Without a group the jet is linear in an interval's coordinates e = (x, v, X2, V1, bubbles, λ)
// (galerkin_flat.hpp), so for such a model the interval gradient g(e) = (∂L~/∂y, C) is affine in
// e with the constant Hessian H of IntervalDerivatives:
//   g(e) = g(e_ref) + H (e - e_ref)
// exactly, for any reference interval e_ref. A step's residual F = (A_l g_{n-1} + A_r g_n) / h
// (FlatStepMaps) then needs H times a vector instead of the model in duals at every Gauss point
// (electron Galerkin 4: a 12 x 12 product against ~250 ns of the model in Dual<9>). Its rounding
// is of the same kind as the model's: u (|g(e_ref)| + |H| |e - e_ref|), against the model's
// u |terms| ~ u |H| |e|.
#pragma once

#include "galerkin_flat.hpp"
#include "galerkin_step.hpp"
#include "newton.hpp"

namespace lpshoot {

// The interval gradient of an affine model, from one interval's derivatives.
template <class Sch>
struct AffineIntervalGradient {
  static constexpr int ne = IntervalDerivatives<Sch>::ne;
  IntervalDerivatives<Sch> reference;  // at e_ref: g(e_ref) and the constant H
  Vec<double, ne> at;                  // e_ref

  Vec<double, ne> of(const Interval<Sch, double>& iv) const {
    return reference.gradient + reference.hessian * (flat_interval_coordinates(iv) - at);
  }
};

// Step n of an affine flow from its prediction (the step map z_c + dz · state, galerkin_flow.hpp)
// and one Newton correction on the flow's factored matrix (`chord`, the affine equations' own):
// F at the prediction from interval n-1's carried gradient and interval n's from `gradient`,
// then z <- z - J⁻¹ F. The correction is needed: the map alone is off by δ(dz) |state - state_0|,
// δ(dz) ~ cond(J) u |dz|; after it z solves the step's equations to their rounding. On return
// the carry holds interval n's gradient at z (g at the prediction plus H times the correction).
// As newton_solve's affine case: one residual, one correction, no convergence test (the
// equations are affine and the matrix is theirs), a non-finite residual reported as such.
template <class Sch>
StepReport solve_mapped_affine_step(const AffineIntervalGradient<Sch>& gradient, const ChordMatrix<Sch::unknowns>& chord,
                                    double h, const Interval<Sch, double>& state,
                                    const Vec<double, Sch::unknowns>& predicted, int n, Interval<Sch, double>& z,
                                    StepCarry<Sch>& carry) {
  constexpr int r = Sch::r, nz = Sch::unknowns, nv = Sch::variation, ne = IntervalDerivatives<Sch>::ne;
  StepReport rep;
  rep.step = n;
  rep.iterations = 1;
  rep.condition = chord.condition;
  z = galerkin_step_start<Sch>(state, h, &predicted);
  const Vec<double, ne> g = gradient.of(z);
  Vec<double, nz> F = flat_right_rows<Sch>(g, h);
  F.template head<nv>() += flat_left_rows<Sch>(carry.interval.gradient, h);
  if (!all_finite(F.data(), nz)) return non_finite_step(rep, n);
  rep.residual = F.template lpNorm<Eigen::Infinity>();
  const Vec<double, nz> dz = chord.lu.solve(-F);
  apply_galerkin_correction<Sch>(z, dz, h);
  // The unknowns are interval n's coordinates from X2 on (2r ..).
  carry.interval.gradient = g + gradient.reference.hessian.template rightCols<ne - 2 * r>() * dz;
  carry.valid = true;
  rep.status = StepStatus::Converged;
  return rep;
}

}  // namespace lpshoot
