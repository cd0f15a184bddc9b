// One Galerkin interval's gradient (∂L~/∂y, C) with a group, by the chain rule through the jet
// inputs: the first-order half of galerkin_group_interval.hpp, for the step's Newton residuals
// (issue 9).
//
// With u_i = A_i e(y) + B_i y (JetInputMaps) and φ_i = ℓ + λ_i · χ on the jet made from u_i,
// w_i = h b_i (galerkin_group_interval.hpp's file comment):
//   ∇_y L~ = Σ_i w_i B_iᵀ ∇φ_i + (∂e/∂y)ᵀ μ,   μ = Σ_i w_i A_iᵀ ∇φ_i,   C_{i,c} = w_i χ_c(q_i).
// ∇φ_i is taken in the 3r + 3d jet inputs (Dual<3r + 3d>; the body velocity in the 3d it depends
// on); the ends e and their Jacobian once per
// interval, ζ = log(W exp(h δ)) in Dual<d> and ω1 = Jr(ζ)^{-1} (end velocity) in Dual<2d>,
// chained. The residual path it replaces perturbed the node and ran the ends and every Gauss
// point's jet inputs in Dual<2r + 2d + bubbles> (right_interval_rows; beanie Galerkin 6, Dual<12>:
// the inputs alone were 6% of a step with sensitivities).
#pragma once

#include "galerkin.hpp"
#include "galerkin_flat.hpp"
#include "galerkin_group_interval.hpp"

namespace lpshoot {

// The ends e = (ζ, ω0, ω1) at the interval (δ = 0) and their Jacobian in y (zero in the
// bubble columns, on which they do not depend).
template <class Sch>
void group_curve_ends_jacobian(const typename Sch::Model& model, const Interval<Sch, double>& iv, double h,
                               Vec<double, 3 * Sch::d>& ev,
                               Eigen::Matrix<double, 3 * Sch::d, IntervalDerivatives<Sch>::ny>& De) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d, n = 4 * r + 3 * d;
  using T = Dual<double, n>;
  using TZ = Dual<double, d>;
  using TF = Dual<double, 2 * d>;
  De.setZero();
  typename G::template Tangent<TZ> delta;
  for (int a = 0; a < d; ++a) delta(a) = TZ::variable(0.0, a) * h;  // W exp(h δ)
  const typename G::template Tangent<TZ> zeta = G::log(G::compose(G::template cast<TZ>(iv.W), G::template exp<TZ>(delta)));
  Vec<T, r> x, v, X2, V1;
  Vec<T, d> Om, O1;
  for (int a = 0; a < r; ++a) {
    x(a) = T::variable(iv.x(a), Sch::x_off + a);
    v(a) = T::variable(iv.v(a), Sch::v_off + a);
    X2(a) = T::variable(iv.X2(a), Sch::X2_off + a);
    V1(a) = T::variable(iv.V1(a), Sch::V1_off + a);
  }
  for (int a = 0; a < d; ++a) {
    Om(a) = T::variable(iv.Om(a), Sch::Om_off + a);
    O1(a) = T::variable(iv.O1(a), Sch::O1_off + a);
  }
  const Vec<T, d> omega0 = Om - connection_velocity_of(model, x, v);
  const Vec<T, d> y = group_curve_end_velocity<Sch, T>(model, x, v, X2, V1, Om, O1, h);
  typename G::template Tangent<TF> zf, yf;
  for (int a = 0; a < d; ++a) {
    zf(a) = TF::variable(zeta(a).v, a);
    yf(a) = TF::variable(y(a).v, d + a);
  }
  const typename G::template Tangent<TF> omega1 = right_jacobian_inverse_times<G, TF>(zf, yf);
  for (int a = 0; a < d; ++a) {
    ev(a) = zeta(a).v;
    ev(d + a) = omega0(a).v;
    ev(2 * d + a) = omega1(a).v;
    for (int c = 0; c < d; ++c) De(a, Sch::W_off + c) = zeta(a).d[c];
    for (int c = 0; c < n; ++c) De(d + a, c) = omega0(a).d[c];
    // ω1 = F(ζ, y): Σ_k ∂F/∂ζ_k ∂ζ_k/∂δ + Σ_k ∂F/∂y_k ∂y_k/∂y.
    for (int k = 0; k < d; ++k) {
      const double fz = omega1(a).d[k], fy = omega1(a).d[d + k];
      for (int c = 0; c < d; ++c) De(2 * d + a, Sch::W_off + c) += fz * zeta(k).d[c];
      for (int c = 0; c < n; ++c) De(2 * d + a, c) += fy * y(k).d[c];
    }
  }
}

// (∂L~/∂y, C) at the interval (IntervalDerivatives' gradient layout), by the file comment's
// chain rule: group_interval_derivatives' gradient without its Hessian.
template <class Sch>
Vec<double, IntervalDerivatives<Sch>::ne> group_interval_gradient_chained(const typename Sch::Model& model,
                                                                       const Interval<Sch, double>& iv, double h) {
  using D = IntervalDerivatives<Sch>;
  constexpr int r = Sch::r, d = Sch::d, m = Sch::m, ny = D::ny, ne = 3 * d, nu = 3 * r + 3 * d;
  using TU = Dual<double, nu>;
  using TX = Dual<double, 3 * d>;
  const auto& tab = GalerkinTable<Sch::degree, Sch::gauss>::get();

  Vec<double, ne> ev;
  Eigen::Matrix<double, ne, ny> De;
  group_curve_ends_jacobian<Sch>(model, iv, h, ev, De);
  Vec<double, ny> y;
  y << iv.x, iv.v, iv.Om, iv.X2, iv.V1, iv.O1, Vec<double, d>::Zero(), iv.w.template head<ny - (4 * r + 3 * d)>();
  const JetInputMaps<Sch>& maps = jet_input_maps<Sch>(h);

  Vec<double, D::ne> out = Vec<double, D::ne>::Zero();
  Vec<double, ne> mu = Vec<double, ne>::Zero();
  Vec<double, nu> gu = Vec<double, nu>::Zero();
  for (int i = 0; i < Sch::gauss; ++i) {
    const double w = h * tab.b[i];
    const Vec<double, nu> u = maps.A[i].lazyProduct(ev) + maps.B[i].lazyProduct(y);
    Jet<typename Sch::Model, TU> q;
    for (int a = 0; a < r; ++a) {
      q.p(a) = TU::variable(u(a), a);
      q.dp(a) = TU::variable(u(r + a), r + a);
      q.ddp(a) = TU::variable(u(2 * r + a), 2 * r + a);
    }
    // The body velocity depends on ξ, ξ', ξ'' alone: run in their 3d directions and placed.
    Vec<TX, d> xi0, xi1, xi2, Om, dOm;
    for (int a = 0; a < d; ++a) {
      xi0(a) = TX::variable(u(3 * r + a), a);
      xi1(a) = TX::variable(u(3 * r + d + a), d + a);
      xi2(a) = TX::variable(u(3 * r + 2 * d + a), 2 * d + a);
    }
    body_velocity_jet<typename Sch::Group, TX>(xi0, xi1, xi2, Om, dOm);
    for (int a = 0; a < d; ++a) {
      q.Omega(a).v = Om(a).v, q.dOmega(a).v = dOm(a).v;
      for (int c = 0; c < 3 * d; ++c) q.Omega(a).d[3 * r + c] = Om(a).d[c], q.dOmega(a).d[3 * r + c] = dOm(a).d[c];
    }
    add_connection_part<Sch, TU>(model, q);
    Vec<TU, m> chi;
    const TU phi = multiplier_integrand<Sch>(model, q, iv, i, chi);
    for (int c = 0; c < m; ++c) out(ny + i * m + c) = w * chi(c).v;
    for (int a = 0; a < nu; ++a) gu(a) = w * phi.d[a];
    out.template head<ny>().noalias() += maps.B[i].transpose().lazyProduct(gu);
    mu.noalias() += maps.A[i].transpose().lazyProduct(gu);
  }
  out.template head<ny>().noalias() += De.transpose().lazyProduct(mu);
  return out;
}

}  // namespace lpshoot
