// One Galerkin interval's L~ = L0 + λ · C with its gradient and Hessian in its coordinates, with
// a group (d > 0; issue 9). y = (x, v, Ω, X2, V1, O1, δ, bubbles) in the state's layout, W moved
// to W exp(h δ), and the multipliers λ.
//
// By the chain rule through each Gauss point's jet inputs u = (p, p', p'', ξ, ξ', ξ'')
// (galerkin.hpp, jet_inputs_at), 3r + 3d of them. They are linear in y and in the group curve's
// ends e = (ζ, ω0, ω1) (3d values, nonlinear in y: ζ = log(W exp(h δ)), ω1 = Jr(ζ)^{-1} (...)):
//   u_i = A_i e(y) + B_i y,   ∂u_i/∂y = J_i = A_i ∂e/∂y + B_i,   ∇²u_i = Σ_j (A_i)_{·j} ∇²e_j.
// With φ_i = ℓ + λ_i · χ on the jet made from u_i (jet_from_inputs), w_i = h b_i:
//   ∇_y L~  = Σ_i w_i J_iᵀ ∇φ_i,
//   ∇²_y L~ = Σ_i w_i J_iᵀ ∇²φ_i J_i + Σ_j μ_j ∇²e_j,   μ = Σ_i w_i A_iᵀ ∇φ_i,
//   ∂C_{i,c}/∂y = w_i J_iᵀ ∇χ_c.
// ∇φ_i and ∇²φ_i are taken in the 3r + 3d directions of u (Hess<3r + 3d>); only e carries the
// interval's directions, once per interval and in the 4r + 3d it depends on (not the bubbles):
// the body velocity's closed form and ℓ no longer run in Hess<ny>. Used where 3r + 3d < ny;
// otherwise the direct evaluation (group_interval_derivatives_direct), which is also the
// tests' reference. Beanie, Galerkin 6: Hess<12> per Gauss point and Hess<13> for e, instead of
// Hess<17> throughout.
#pragma once

#include "galerkin.hpp"
#include "galerkin_flat.hpp"
#include "group_velocity_hessian.hpp"
#include "hessian_scalar.hpp"

namespace lpshoot {

// The state interval with its smooth tangent coordinates (all but the multipliers, the last
// Q m) seeded in columns first .. first + state - Q m - 1 of T.
template <class Sch, class T>
Interval<Sch, T> seeded_state(const Interval<Sch, double>& state, double h, int first) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d, nb = Sch::aux - multiplier_count<Sch>;
  Interval<Sch, T> s = state.template cast<T>();
  for (int a = 0; a < r; ++a) {
    s.x(a) = T::variable(state.x(a), first + Sch::x_off + a);
    s.v(a) = T::variable(state.v(a), first + Sch::v_off + a);
    s.X2(a) = T::variable(state.X2(a), first + Sch::X2_off + a);
    s.V1(a) = T::variable(state.V1(a), first + Sch::V1_off + a);
  }
  for (int a = 0; a < d; ++a) {
    s.Om(a) = T::variable(state.Om(a), first + Sch::Om_off + a);
    s.O1(a) = T::variable(state.O1(a), first + Sch::O1_off + a);
  }
  if constexpr (d > 0) {
    typename G::template Tangent<T> delta;
    for (int a = 0; a < d; ++a) delta(a) = T::variable(0.0, first + Sch::W_off + a) * h;  // W exp(h δ)
    s.W = G::compose(s.W, G::template exp<T>(delta));
  }
  for (int a = 0; a < nb; ++a) s.w(a) = T::variable(state.w(a), first + Sch::aux_off + a);
  return s;
}

// One interval's L~ = L0 + λ · C with its gradient and Hessian in (y, λ) (y in the state's
// layout, W exp(h δ)), from one evaluation in Hess<ny>: every step of the jet carries all ny
// directions. The reference for group_interval_derivatives.
template <class Sch>
IntervalDerivatives<Sch> group_interval_derivatives_direct(const typename Sch::Model& model, const Interval<Sch, double>& iv,
                                                    double h) {
  using D = IntervalDerivatives<Sch>;
  constexpr int ny = D::ny, nm = D::nm;
  using T = Hess<ny>;
  const Interval<Sch, T> s = seeded_state<Sch, T>(iv, h, 0);
  T L0;
  Vec<T, nm> C;
  interval_parts(model, s, h, L0, C);
  D out;
  out.hessian.setZero();
  for (int c = 0; c < nm; ++c) {
    const double lambda = iv.w(Sch::multipliers(0) + c);
    if (lambda != 0.0) add_scaled(L0, lambda, C(c));
    out.gradient(ny + c) = C(c).v;
    for (int i = 0; i < ny; ++i) out.hessian(i, ny + c) = out.hessian(ny + c, i) = C(c).g[i];
  }
  unpack_derivatives(L0, out.gradient, out.hessian);
  return out;
}

// The linear maps of jet_inputs_at, u_i = A_i e + B_i y (see the file comment), at every Gauss
// point for one h: jet_inputs_at has no constant term, and its coefficients depend on h only.
// Read off one evaluation in first-order duals (y in directions 0 .. ny-1, e after).
template <class Sch>
struct JetInputMaps {
  static constexpr int r = Sch::r, d = Sch::d, nu = 3 * r + 3 * d, ny = IntervalDerivatives<Sch>::ny, ne = 3 * d;
  using TL = Dual<double, ny + ne>;
  double h = 0;
  std::array<Eigen::Matrix<double, nu, ne>, Sch::gauss> A;
  std::array<Eigen::Matrix<double, nu, ny>, Sch::gauss> B;

  explicit JetInputMaps(double step) : h(step) {
    Interval<Sch, double> zero;
    zero.x.setZero(), zero.v.setZero(), zero.X2.setZero(), zero.V1.setZero(), zero.Om.setZero(), zero.O1.setZero();
    zero.w.setZero();
    Interval<Sch, TL> iv = zero.template cast<TL>();
    for (int a = 0; a < r; ++a) {
      iv.x(a) = TL::variable(0.0, Sch::x_off + a);
      iv.v(a) = TL::variable(0.0, Sch::v_off + a);
      iv.X2(a) = TL::variable(0.0, Sch::X2_off + a);
      iv.V1(a) = TL::variable(0.0, Sch::V1_off + a);
    }
    for (int a = 0; a < Sch::aux - multiplier_count<Sch>; ++a) iv.w(a) = TL::variable(0.0, Sch::aux_off + a);
    GroupCurveEnds<Sch, TL> e;
    for (int a = 0; a < d; ++a) {
      e.zeta(a) = TL::variable(0.0, ny + a);
      e.omega0(a) = TL::variable(0.0, ny + d + a);
      e.omega1(a) = TL::variable(0.0, ny + 2 * d + a);
    }
    for (int i = 0; i < Sch::gauss; ++i) {
      const JetInputs<Sch, TL> u = jet_inputs_at(iv, e, i, h);
      int k = 0;
      auto put = [&](const TL& x) {
        for (int c = 0; c < ny; ++c) B[i](k, c) = x.d[c];
        for (int c = 0; c < ne; ++c) A[i](k, c) = x.d[ny + c];
        ++k;
      };
      for (int a = 0; a < r; ++a) put(u.p(a));
      for (int a = 0; a < r; ++a) put(u.dp(a));
      for (int a = 0; a < r; ++a) put(u.ddp(a));
      for (int a = 0; a < d; ++a) put(u.xi0(a));
      for (int a = 0; a < d; ++a) put(u.xi1(a));
      for (int a = 0; a < d; ++a) put(u.xi2(a));
    }
  }
};

// The maps for h, rebuilt when h changes (one set per thread: a flow's steps share h).
template <class Sch>
const JetInputMaps<Sch>& jet_input_maps(double h) {
  thread_local JetInputMaps<Sch> maps(h);
  if (maps.h != h) maps = JetInputMaps<Sch>(h);
  return maps;
}

// The group curve's ends e(y) in Hess<4r + 3d> over (x, v, Ω, X2, V1, O1, δ), the first
// 4r + 3d directions of group_curve_ends of seeded_state(iv, h, 0). ζ = log(W exp(h δ)) depends on
// δ alone: its group operations run in Hess<d> and are embedded, instead of in all 4r + 3d
// directions with the whole interval cast to T (beanie: 18% of a Galerkin 4 step with
// sensitivities went to them).
template <class Sch>
GroupCurveEnds<Sch, Hess<4 * Sch::r + 3 * Sch::d>> seeded_group_curve_ends(const typename Sch::Model& model,
                                                                          const Interval<Sch, double>& iv, double h) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d, n = 4 * r + 3 * d;
  using T = Hess<n>;
  using TZ = Hess<d>;
  typename G::template Tangent<TZ> delta;
  for (int a = 0; a < d; ++a) delta(a) = TZ::variable(0.0, a) * h;  // W exp(h δ)
  const typename G::template Tangent<TZ> zeta_d = G::log(G::compose(G::template cast<TZ>(iv.W), G::template exp<TZ>(delta)));
  Vec<T, d> zeta, Om, O1;
  Vec<T, r> x, v, X2, V1;
  for (int a = 0; a < d; ++a) {  // the vectors start at zero: seeded in place (hessian_scalar.hpp)
    add_embedded(zeta(a), zeta_d(a), Sch::W_off);
    make_variable_in_place(Om(a), iv.Om(a), Sch::Om_off + a);
    make_variable_in_place(O1(a), iv.O1(a), Sch::O1_off + a);
  }
  for (int a = 0; a < r; ++a) {
    make_variable_in_place(x(a), iv.x(a), Sch::x_off + a);
    make_variable_in_place(v(a), iv.v(a), Sch::v_off + a);
    make_variable_in_place(X2(a), iv.X2(a), Sch::X2_off + a);
    make_variable_in_place(V1(a), iv.V1(a), Sch::V1_off + a);
  }
  // group_curve_ends_from, with ω1 = Jr(ζ)^{-1} y (y the end velocity) taken as a function of
  // its 2d arguments in Hess<2d> and composed: ζ depends on δ alone and y on a few coordinates,
  // so the composition touches few entries where Hess<4r + 3d> arithmetic touched all.
  GroupCurveEnds<Sch, T> e;
  e.zeta = zeta;
  e.omega0 = Om - connection_velocity_of(model, x, v);
  const Vec<T, d> y = group_curve_end_velocity<Sch, T>(model, x, v, X2, V1, Om, O1, h);
  using TF = Hess<2 * d>;
  typename G::template Tangent<TF> zf, yf;
  const T* args[2 * d];
  for (int a = 0; a < d; ++a) {
    zf(a) = TF::variable(zeta(a).v, a);
    yf(a) = TF::variable(y(a).v, d + a);
    args[a] = &e.zeta(a);
    args[d + a] = &y(a);
  }
  const typename G::template Tangent<TF> F = right_jacobian_inverse_times<G, TF>(zf, yf);
  for (int a = 0; a < d; ++a) e.omega1(a) = detail::compose_sparse<n, 2 * d>(F(a), args);
  return e;
}

// jet_from_inputs at the jet inputs u = (p, p', p'', ξ, ξ', ξ'') (JetInputMaps' order), seeded
// in Hess<3r + 3d>. The body velocity depends on the 3d inputs ξ, ξ', ξ'' alone: it runs in
// Hess<3d> and is embedded (beanie: Hess<9> instead of Hess<12>, where a fifth of a Galerkin 4
// step with sensitivities went).
template <class Sch>
Jet<typename Sch::Model, Hess<3 * Sch::r + 3 * Sch::d>> seeded_jet(const typename Sch::Model& model,
                                                                   const Vec<double, 3 * Sch::r + 3 * Sch::d>& u) {
  constexpr int r = Sch::r, d = Sch::d, nu = 3 * r + 3 * d;
  using T = Hess<nu>;
  using TX = Hess<3 * d>;
  Jet<typename Sch::Model, T> q;
  for (int a = 0; a < r; ++a) {  // q's scalars start at zero
    q.p(a).v = u(a), q.p(a).g[a] = 1.0;
    q.dp(a).v = u(r + a), q.dp(a).g[r + a] = 1.0;
    q.ddp(a).v = u(2 * r + a), q.ddp(a).g[2 * r + a] = 1.0;
  }
  using G = typename Sch::Group;
  if constexpr (SeededVelocity<G>::available) {
    // Closed form, straight into the jet's directions (group_velocity_hessian.hpp).
    const auto idx = [](int k, int a) { return 3 * r + k * d + a; };
    SeededVelocity<G>::template jet<nu>(u.data() + 3 * r, u.data() + 3 * r + d, u.data() + 3 * r + 2 * d, idx,
                                        q.Omega.data(), q.dOmega.data());
  } else {
    Vec<TX, d> xi0, xi1, xi2, Om, dOm;
    for (int a = 0; a < d; ++a) {
      xi0(a) = TX::variable(u(3 * r + a), a);
      xi1(a) = TX::variable(u(3 * r + d + a), d + a);
      xi2(a) = TX::variable(u(3 * r + 2 * d + a), 2 * d + a);
    }
    body_velocity_jet<G, TX>(xi0, xi1, xi2, Om, dOm);
    for (int a = 0; a < d; ++a) {  // q's scalars start at zero
      add_embedded(q.Omega(a), Om(a), 3 * r);
      add_embedded(q.dOmega(a), dOm(a), 3 * r);
    }
  }
  // + 𝒜(p) p' and its time derivative: functions of (p, p', p''), the first 3r directions, run
  // in Hess<3r> and added (the beanie's constant 𝒜 made full Hess<3r + 3d> sums).
  if constexpr (detail::HasConnectionForm<typename Sch::Model, Hess<3 * r>>::value) {
    using TP = Hess<3 * r>;
    Vec<TP, r> p, dp, ddp;
    for (int a = 0; a < r; ++a) {
      p(a) = TP::variable(u(a), a);
      dp(a) = TP::variable(u(r + a), r + a);
      ddp(a) = TP::variable(u(2 * r + a), 2 * r + a);
    }
    Vec<TP, d> cv, dcv;
    connection_jet(model, p, dp, ddp, cv, dcv);
    for (int a = 0; a < d; ++a) {
      add_embedded(q.Omega(a), cv(a), 0);
      add_embedded(q.dOmega(a), dcv(a), 0);
    }
  }
  return q;
}

// The file comment's chain rule.
template <class Sch>
IntervalDerivatives<Sch> group_interval_derivatives_chained(const typename Sch::Model& model,
                                                            const Interval<Sch, double>& iv, double h) {
  using D = IntervalDerivatives<Sch>;
  constexpr int r = Sch::r, d = Sch::d, m = Sch::m, ny = D::ny, ne = 3 * d, nu = 3 * r + 3 * d;
  constexpr int ny_e = 4 * r + 3 * d;  // x, v, Ω, X2, V1, O1, δ: the ends' arguments
  using TE = Hess<ny_e>;
  using TU = Hess<nu>;
  const auto& tab = GalerkinTable<Sch::degree, Sch::gauss>::get();

  // The ends e(y) with their gradients and Hessians. They do not depend on the bubbles, the
  // last coordinates of y: Hess in the first ny_e only.
  const GroupCurveEnds<Sch, TE> ends = seeded_group_curve_ends<Sch>(model, iv, h);
  const TE* e[ne];
  for (int a = 0; a < d; ++a) e[a] = &ends.zeta(a), e[d + a] = &ends.omega0(a), e[2 * d + a] = &ends.omega1(a);
  Eigen::Matrix<double, ne, ny> De = Eigen::Matrix<double, ne, ny>::Zero();
  Vec<double, ne> ev;
  for (int j = 0; j < ne; ++j) {
    ev(j) = e[j]->v;
    for (int c = 0; c < ny_e; ++c) De(j, c) = e[j]->g[c];
  }
  // y (δ = 0: W is the base point of its perturbation).
  Vec<double, ny> y;
  y << iv.x, iv.v, iv.Om, iv.X2, iv.V1, iv.O1, Vec<double, d>::Zero(), iv.w.template head<ny - ny_e>();
  const JetInputMaps<Sch>& maps = jet_input_maps<Sch>(h);

  D out;
  out.gradient.setZero();
  out.hessian.setZero();
  Eigen::Matrix<double, ny, ny> H = Eigen::Matrix<double, ny, ny>::Zero();
  Vec<double, ne> mu = Vec<double, ne>::Zero();
  for (int i = 0; i < Sch::gauss; ++i) {
    const double w = h * tab.b[i];
    const Eigen::Matrix<double, nu, ne>& A = maps.A[i];
    const Vec<double, nu> u = A.lazyProduct(ev) + maps.B[i].lazyProduct(y);
    const Eigen::Matrix<double, nu, ny> Ju = maps.B[i] + A.lazyProduct(De);
    const Jet<typename Sch::Model, TU> q = seeded_jet<Sch>(model, u);
    Vec<TU, m> chi;
    const TU phi = multiplier_integrand<Sch>(model, q, iv, i, chi);
    if constexpr (m > 0) {
      for (int c = 0; c < m; ++c) {
        const int k = i * m + c;
        out.gradient(ny + k) = w * chi(c).v;
        Vec<double, nu> gc;
        for (int a = 0; a < nu; ++a) gc(a) = chi(c).g[a];
        out.hessian.col(ny + k).template head<ny>().noalias() = w * Ju.transpose().lazyProduct(gc);
        out.hessian.row(ny + k).template head<ny>() = out.hessian.col(ny + k).template head<ny>().transpose();
      }
    }
    Vec<double, nu> g;
    Eigen::Matrix<double, nu, nu> Hu;
    for (int a = 0; a < nu; ++a) {
      g(a) = phi.g[a];
      for (int b = a; b < nu; ++b) Hu(a, b) = Hu(b, a) = phi.H[TU::at(a, b)];
    }
    out.gradient.template head<ny>().noalias() += w * Ju.transpose().lazyProduct(g);
    const Eigen::Matrix<double, nu, ny> HJ = Hu.lazyProduct(Ju);
    H.noalias() += w * Ju.transpose().lazyProduct(HJ);
    mu.noalias() += w * A.transpose().lazyProduct(g);
  }
  // + Σ_j μ_j ∇²e_j (packed upper triangles, the first ny_e coordinates); the upper triangle
  // is the result, mirrored.
  int k = 0;
  for (int a = 0; a < ny; ++a)
    for (int b = a; b < ny; ++b) {
      double s = H(a, b);
      if (b < ny_e) {
        for (int j = 0; j < ne; ++j) s += mu(j) * e[j]->H[k];
        ++k;
      }
      out.hessian(a, b) = out.hessian(b, a) = s;
    }
  return out;
}

// L~'s derivatives: by the chain rule where the jet has fewer inputs than the interval has
// coordinates, directly otherwise.
template <class Sch>
constexpr bool chains_interval_derivatives = 3 * Sch::r + 3 * Sch::d < IntervalDerivatives<Sch>::ny;

template <class Sch>
IntervalDerivatives<Sch> group_interval_derivatives(const typename Sch::Model& model, const Interval<Sch, double>& iv,
                                                    double h) {
  if constexpr (chains_interval_derivatives<Sch>)
    return group_interval_derivatives_chained<Sch>(model, iv, h);
  else
    return group_interval_derivatives_direct<Sch>(model, iv, h);
}

}  // namespace lpshoot
