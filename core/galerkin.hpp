// Galerkin discretizations of a continuous reduced problem (METHOD.md §9): Hermite curves of
// degree S on node states, Q Gauss–Legendre points, written in increments.
//
// Node n carries (x_n, v_n, Ω_n): shape, shape velocity and reduced group velocity; interval n
// carries scaled increments (X2, V1, O1) with
//   x_{n+1} = x_n + h v_n + h² X2,  v_{n+1} = v_n + h V1,  Ω_{n+1} = Ω_n + h O1,
// the group increment W_n = g_n^{-1} g_{n+1}, S - 3 bubble coefficients per shape and group
// component and m multipliers per Gauss point. On the interval (τ = (t - t_n)/h),
//   p(τ) = x_n + h v_n τ + h² (X2 H01 + V1 H11 + Σ a_j β_j)            (no nearly-equal nodes)
//   g(τ) = g_n exp(ξ(τ)),  ξ = h ω_n H10 + log(W_n) H01 + h Jr(log W_n)^{-1} ω_{n+1} H11 + h² Σ c_j β_j
// with ω = Ω − 𝒜(p) p' the body velocity at the nodes (METHOD.md §9 route (a): ξ Hermite in the
// algebra, so g is C¹ and L_d depends on g only through W_n: the discrete momentum map is
// conserved). The discrete Lagrangian is the Gauss quadrature of ℓ plus the constraints at the
// Gauss points:
//   L~_n = h Σ_i b_i [ℓ(q(τ_i)) + λ_i · χ(q(τ_i))].
// Order 2S − 2 with Q = S − 1 points; fewer points leave the step matrix singular.
#pragma once

#include "connection_jet.hpp"
#include "continuous.hpp"
#include "group_jets.hpp"
#include "hermite.hpp"

namespace lpshoot {

template <class C, int S = 3, int Q = S - 1>
struct Galerkin {
  using Model = C;
  using Group = typename C::Group;
  static constexpr int r = C::shape_dim, d = Group::dim, m = C::num_constraints;
  static constexpr int degree = S, gauss = Q, bubbles = S - 3;
  static constexpr int order = 2 * S - 2;             // with Q = S - 1
  static constexpr int node = 2 * r + d;               // (x, v, Ω)
  static constexpr int variation = 2 * r + 2 * d;      // node perturbation (δx, δv, δΩ, η)
  static constexpr int aux = bubbles * (r + d) + Q * m;  // bubbles, then multipliers
  static constexpr int unknowns = node + d + aux;      // one step: (X2, V1, O1), ζ, aux
  static constexpr int state = node + unknowns;        // an interval: base node + its unknowns
  // Offsets in an interval's tangent coordinates (W is perturbed as W exp(h δ)).
  static constexpr int x_off = 0, v_off = r, Om_off = 2 * r;
  static constexpr int X2_off = node, V1_off = node + r, O1_off = node + 2 * r, W_off = 2 * node,
                       aux_off = 2 * node + d;
  static constexpr int shape_bubble(int j) { return j * r; }  // within aux
  static constexpr int group_bubble(int j) { return bubbles * r + j * d; }
  static constexpr int multipliers(int i) { return bubbles * (r + d) + i * m; }
  static_assert(S >= 3 && S <= 6, "Galerkin curves of degree 3 (order 4) to 6");
  static_assert(Q >= 1 && Q <= 5, "1 to 5 Gauss points");
  static_assert(r >= 1, "the shape space must have dimension at least 1");
};

// One interval in increment form (see the file comment), in scalar T.
template <class Sch, class T>
struct Interval {
  using G = typename Sch::Group;
  Vec<T, Sch::r> x, v, X2, V1;
  Vec<T, Sch::d> Om, O1;
  typename G::template Element<T> W = G::template identity<T>();
  Vec<T, Sch::aux> w;

  Vec<T, Sch::r> x_end(double h) const { return x + h * v + (h * h) * X2; }
  Vec<T, Sch::r> v_end(double h) const { return v + h * V1; }
  Vec<T, Sch::d> Om_end(double h) const { return Om + h * O1; }

  template <class TO>
  Interval<Sch, TO> cast() const {
    Interval<Sch, TO> o;
    o.x = x.template cast<TO>(), o.v = v.template cast<TO>(), o.X2 = X2.template cast<TO>();
    o.V1 = V1.template cast<TO>(), o.Om = Om.template cast<TO>(), o.O1 = O1.template cast<TO>();
    o.W = G::template cast<TO>(W);
    o.w = w.template cast<TO>();
    return o;
  }
};

// The interval's ξ end data (METHOD.md §9 route (a)): ζ = log W, ω0 and the end slope
// Jr(ζ)^{-1} ω1 (so that the body velocity of g_n exp(ξ) at the end node is ω1).
template <class Sch, class T>
struct GroupCurveEnds {
  Vec<T, Sch::d> zeta, omega0, omega1;
};

// The group curve's velocity at the interval's end, Ω_end − 𝒜(x_end) v_end, from its base node
// and increments (the interval's x_end, v_end and Om_end, written out: galerkin_group_interval.hpp
// calls it on separately seeded coordinates).
template <class Sch, class T>
Vec<T, Sch::d> group_curve_end_velocity(const typename Sch::Model& model, const Vec<T, Sch::r>& x,
                                        const Vec<T, Sch::r>& v, const Vec<T, Sch::r>& X2, const Vec<T, Sch::r>& V1,
                                        const Vec<T, Sch::d>& Om, const Vec<T, Sch::d>& O1, double h) {
  const Vec<T, Sch::r> x_end = x + h * v + (h * h) * X2, v_end = v + h * V1;
  return (Om + h * O1) - connection_velocity_of(model, x_end, v_end);
}

// The ends from ζ = log W and the interval's base node and increments.
template <class Sch, class T>
GroupCurveEnds<Sch, T> group_curve_ends_from(const typename Sch::Model& model, const Vec<T, Sch::d>& zeta,
                                             const Vec<T, Sch::r>& x, const Vec<T, Sch::r>& v,
                                             const Vec<T, Sch::r>& X2, const Vec<T, Sch::r>& V1,
                                             const Vec<T, Sch::d>& Om, const Vec<T, Sch::d>& O1, double h) {
  GroupCurveEnds<Sch, T> e;
  e.zeta = zeta;
  e.omega0 = Om - connection_velocity_of(model, x, v);
  const Vec<T, Sch::d> end_velocity = group_curve_end_velocity<Sch, T>(model, x, v, X2, V1, Om, O1, h);
  e.omega1 = right_jacobian_inverse_times<typename Sch::Group, T>(zeta, end_velocity);
  return e;
}

template <class Sch, class T>
GroupCurveEnds<Sch, T> group_curve_ends(const typename Sch::Model& model, const Interval<Sch, T>& iv, double h) {
  return group_curve_ends_from<Sch, T>(model, Sch::Group::log(iv.W), iv.x, iv.v, iv.X2, iv.V1, iv.Om, iv.O1, h);
}

// What the jet at Gauss point i is made of: p, p', p'' and the time derivatives ξ, ξ', ξ'' of
// the group curve's algebra part (absent without a group). They are linear in the interval's
// shape coordinates (x, v, X2, V1, shape bubbles) and in the group curve's ends and bubbles;
// the jet is nonlinear in them only through the body velocity and the connection
// (jet_from_inputs). galerkin_group.hpp differentiates the two stages separately.
template <class Sch, class T>
struct JetInputs {
  Vec<T, Sch::r> p, dp, ddp;
  Vec<T, Sch::d> xi0, xi1, xi2;
};

template <class Sch, class T>
JetInputs<Sch, T> jet_inputs_at(const Interval<Sch, T>& iv, const GroupCurveEnds<Sch, T>& ends, int i, double h) {
  constexpr int r = Sch::r, d = Sch::d;
  const auto& B = GalerkinTable<Sch::degree, Sch::gauss>::get().basis[i];
  const double tau = GalerkinTable<Sch::degree, Sch::gauss>::get().c[i];
  // Shape: the k-th time derivative of h²(X2 H01 + V1 H11 + Σ a_j β_j) is h^(2-k) times this.
  auto shape_part = [&](int k) {
    Vec<T, r> s;
    for (int a = 0; a < r; ++a) {
      s(a) = B[2][k] * iv.X2(a);
      add_scaled(s(a), B[3][k], iv.V1(a));
      for (int j = 0; j < Sch::bubbles; ++j) add_scaled(s(a), B[4 + j][k], iv.w(Sch::shape_bubble(j) + a));
    }
    return s;
  };
  JetInputs<Sch, T> u;
  u.p = shape_part(0);
  u.dp = shape_part(1);
  for (int a = 0; a < r; ++a) {
    u.p(a) = u.p(a) * (h * h);
    add_scaled(u.p(a), 1.0, iv.x(a));
    add_scaled(u.p(a), h * tau, iv.v(a));
    u.dp(a) = u.dp(a) * h;
    add_scaled(u.dp(a), 1.0, iv.v(a));
  }
  u.ddp = shape_part(2);
  if constexpr (d > 0) {
    // The time derivatives ξ^(k)(t_i), k = 0, 1, 2 (h^(-k) times the τ-derivatives).
    auto xi_derivative = [&](int k) {
      const double hk = k == 0 ? 1.0 : k == 1 ? 1.0 / h : 1.0 / (h * h);
      Vec<T, d> s;
      for (int a = 0; a < d; ++a) {
        s(a) = (h * hk * B[1][k]) * ends.omega0(a);
        add_scaled(s(a), hk * B[2][k], ends.zeta(a));
        add_scaled(s(a), h * hk * B[3][k], ends.omega1(a));
        for (int j = 0; j < Sch::bubbles; ++j) add_scaled(s(a), h * h * hk * B[4 + j][k], iv.w(Sch::group_bubble(j) + a));
      }
      return s;
    };
    u.xi0 = xi_derivative(0);
    u.xi1 = xi_derivative(1);
    u.xi2 = xi_derivative(2);
  }
  return u;
}

// Ω += 𝒜(p) p' and Ω' += its time derivative (nothing without a connection form), for
// galerkin_group_interval.hpp's seeded_jet. jet_from_inputs writes the same inline: called
// there, GCC left this call out of line in the residuals (Dual<12>), 4% slower on Galerkin 6.
template <class Sch, class T>
void add_connection_part(const typename Sch::Model& model, Jet<typename Sch::Model, T>& q) {
  if constexpr (detail::HasConnectionForm<typename Sch::Model, T>::value) {
    Vec<T, Sch::d> cv, dcv;
    connection_jet(model, q.p, q.dp, q.ddp, cv, dcv);
    q.Omega += cv;
    q.dOmega += dcv;
  }
  (void)model, (void)q;
}

// The jet q = (p, p', p'', Ω, Ω') from its inputs: Ω, Ω' the body velocity of exp(ξ) and its
// derivative, plus 𝒜(p) p' and its time derivative.
template <class Sch, class T>
Jet<typename Sch::Model, T> jet_from_inputs(const typename Sch::Model& model, const JetInputs<Sch, T>& u) {
  using C = typename Sch::Model;
  Jet<C, T> q;
  q.p = u.p;
  q.dp = u.dp;
  q.ddp = u.ddp;
  if constexpr (Sch::d > 0) {
    body_velocity_jet<typename Sch::Group, T>(u.xi0, u.xi1, u.xi2, q.Omega, q.dOmega);
    if constexpr (detail::HasConnectionForm<C, T>::value) {  // + 𝒜(p) p' and its time derivative
      Vec<T, Sch::d> cv, dcv;
      connection_jet(model, q.p, q.dp, q.ddp, cv, dcv);
      q.Omega += cv;
      q.dOmega += dcv;
    }
  }
  (void)model;
  return q;
}

// The jet q = (p, p', p'', Ω, Ω') at Gauss point i.
template <class Sch, class T>
Jet<typename Sch::Model, T> jet_at(const typename Sch::Model& model, const Interval<Sch, T>& iv,
                                   const GroupCurveEnds<Sch, T>& ends, int i, double h) {
  return jet_from_inputs<Sch, T>(model, jet_inputs_at(iv, ends, i, h));
}

// The two parts of L~ = L0 + λ · C on one interval: L0 = h Σ_i b_i ℓ(q_i) and the constraint
// terms C_{i,c} = h b_i χ_c(q_i) (multiplier layout). L~ is linear in the multipliers, which the
// step's derivatives exploit (galerkin_step.hpp).
template <class Sch>
constexpr int multiplier_count = Sch::gauss * Sch::m;

template <class Sch, class T>
void interval_parts(const typename Sch::Model& model, const Interval<Sch, T>& iv, double h, T& L0,
                    Vec<T, multiplier_count<Sch>>& C) {
  constexpr int m = Sch::m;
  const auto& tab = GalerkinTable<Sch::degree, Sch::gauss>::get();
  GroupCurveEnds<Sch, T> ends;
  if constexpr (Sch::d > 0) ends = group_curve_ends(model, iv, h);
  L0 = T(0.0);
  for (int i = 0; i < Sch::gauss; ++i) {
    const auto q = jet_at(model, iv, ends, i, h);
    add_scaled(L0, h * tab.b[i], model.template lagrangian<T>(q));
    if constexpr (m > 0) {
      const Vec<T, m> chi = model.template constraints<T>(q);
      for (int c = 0; c < m; ++c) C(i * m + c) = (h * tab.b[i]) * chi(c);
    }
  }
}

// The integrand of L~ at Gauss point i with its multipliers, φ = ℓ(q) + Σ_c λ_{i,c} χ_c(q), and
// χ(q) in `chi`: what the chain-rule derivatives of L~ differentiate (galerkin_group_gradient.hpp,
// galerkin_group_interval.hpp).
template <class Sch, class T>
T multiplier_integrand(const typename Sch::Model& model, const Jet<typename Sch::Model, T>& q,
                       const Interval<Sch, double>& iv, int i, Vec<T, Sch::m>& chi) {
  T phi = model.template lagrangian<T>(q);
  if constexpr (Sch::m > 0) {
    chi = model.template constraints<T>(q);
    for (int c = 0; c < Sch::m; ++c) add_scaled(phi, iv.w(Sch::multipliers(0) + i * Sch::m + c), chi(c));
  }
  return phi;
}

// L~ of one interval: h Σ_i b_i [ℓ(q_i) + λ_i · χ(q_i)].
template <class Sch, class T>
T interval_action(const typename Sch::Model& model, const Interval<Sch, T>& iv, double h) {
  constexpr int nm = multiplier_count<Sch>;
  T L;
  Vec<T, nm> C;
  interval_parts(model, iv, h, L, C);
  for (int k = 0; k < nm; ++k) L = L + iv.w(Sch::multipliers(0) + k) * C(k);
  return L;
}

// The cost part of an interval (without the multiplier terms): h Σ_i b_i ℓ(q_i).
template <class Sch>
double interval_cost(const typename Sch::Model& model, const Interval<Sch, double>& iv, double h) {
  const auto& tab = GalerkinTable<Sch::degree, Sch::gauss>::get();
  GroupCurveEnds<Sch, double> ends;
  if constexpr (Sch::d > 0) ends = group_curve_ends(model, iv, h);
  double L = 0;
  for (int i = 0; i < Sch::gauss; ++i) L += h * tab.b[i] * model.template lagrangian<double>(jet_at(model, iv, ends, i, h));
  return L;
}

// E_n: the derivative of L~(left) + L~(right) with respect to node n, divided by h, in scaled
// node directions e = (e_x, e_v, e_Ω, e_η): δx = h² e_x, δv = h e_v, δΩ = h e_Ω, η = h e_η (so
// that every row is O(1)). Node n is the end of `left` (interval n-1) and the base of `right`
// (interval n): left's increments take the perturbation, right's base takes it and right's
// increments compensate (its end node stays). Either may be null at a boundary: the result is
// then the natural boundary condition of that end.
template <class Sch, class TO, class TI>
void perturb_node(const Interval<Sch, TO>* left, const Interval<Sch, TO>* right, double h, Interval<Sch, TI>& l,
                  Interval<Sch, TI>& q) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d;
  Vec<TI, r> ex, ev;
  Vec<TI, d> eO;
  typename G::template Tangent<TI> eta;
  for (int a = 0; a < r; ++a) {
    ex(a) = TI::variable(TO(0.0), a);
    ev(a) = TI::variable(TO(0.0), r + a);
  }
  for (int a = 0; a < d; ++a) {
    eO(a) = TI::variable(TO(0.0), 2 * r + a);
    eta(a) = TI::variable(TO(0.0), 2 * r + d + a);
  }
  if (left) {
    l = left->template cast<TI>();
    l.X2 += ex;
    l.V1 += ev;
    if constexpr (d > 0) {
      l.O1 += eO;
      const typename G::template Tangent<TI> step = h * eta;
      l.W = G::compose(l.W, G::template exp<TI>(step));
    }
  }
  if (right) {
    q = right->template cast<TI>();
    q.x += (h * h) * ex;
    q.v += h * ev;
    q.X2 -= ex + ev;
    q.V1 -= ev;
    if constexpr (d > 0) {
      q.Om += h * eO;
      q.O1 -= eO;
      const typename G::template Tangent<TI> step = -h * eta;
      q.W = G::compose(G::template exp<TI>(step), q.W);
    }
  }
}

template <class Sch, class TO>
Vec<TO, Sch::variation> node_residual(const typename Sch::Model& model, const Interval<Sch, TO>* left,
                                      const Interval<Sch, TO>* right, double h) {
  constexpr int nv = Sch::variation;
  using TI = Dual<TO, nv>;
  Interval<Sch, TI> l, q;
  perturb_node(left, right, h, l, q);
  TI S(0.0);
  if (left) S = S + interval_action(model, l, h);
  if (right) S = S + interval_action(model, q, h);
  Vec<TO, nv> E;
  for (int i = 0; i < nv; ++i) E(i) = S.d[i] / h;
  return E;
}

// ∂E/∂λ of one interval adjacent to the node (the other null): ∂C_k/∂e / h, nv x (Q m). E is
// linear in the interval's multipliers, so this is a first derivative only.
template <class Sch>
Eigen::Matrix<double, Sch::variation, multiplier_count<Sch>> node_multiplier_jacobian(
    const typename Sch::Model& model, const Interval<Sch, double>* left, const Interval<Sch, double>* right, double h) {
  constexpr int nv = Sch::variation, nm = multiplier_count<Sch>;
  using TI = Dual<double, nv>;
  Interval<Sch, TI> l, q;
  perturb_node(left, right, h, l, q);
  TI L0;
  Vec<TI, nm> C;
  interval_parts(model, left ? l : q, h, L0, C);
  Eigen::Matrix<double, nv, nm> D;
  for (int k = 0; k < nm; ++k)
    for (int i = 0; i < nv; ++i) D(i, k) = C(k).d[i] / h;
  return D;
}

// The interval's own equations: ∂L~/∂(bubbles, multipliers), divided by h (the multiplier rows
// are b_i χ(q_i)).
template <class Sch, class TO>
Vec<TO, Sch::aux> aux_residual(const typename Sch::Model& model, const Interval<Sch, TO>& iv, double h) {
  constexpr int na = Sch::aux, nm = multiplier_count<Sch>, nb = na - nm;
  Vec<TO, na> R;
  if constexpr (nb > 0) {  // bubbles: ∂L~/∂a / h
    using TI = Dual<TO, nb>;
    Interval<Sch, TI> q = iv.template cast<TI>();
    for (int a = 0; a < nb; ++a) q.w(a) = TI::variable(iv.w(a), a);
    const TI S = interval_action(model, q, h);
    for (int i = 0; i < nb; ++i) R(i) = S.d[i] / h;
  }
  if constexpr (nm > 0) {  // multipliers: ∂L~/∂λ / h = C / h = b_i χ(q_i)
    TO L0;
    Vec<TO, nm> C;
    interval_parts(model, iv, h, L0, C);
    R.template tail<nm>() = C / h;
  }
  (void)model, (void)iv, (void)h;
  return R;
}

// ∂(bubble rows)/∂λ: ∂C_k/∂a / h, (na - Q m) x (Q m), first derivatives only.
template <class Sch>
Eigen::Matrix<double, Sch::aux - multiplier_count<Sch>, multiplier_count<Sch>> bubble_multiplier_jacobian(
    const typename Sch::Model& model, const Interval<Sch, double>& iv, double h) {
  constexpr int nm = multiplier_count<Sch>, nb = Sch::aux - nm;
  Eigen::Matrix<double, nb, nm> D;
  if constexpr (nb > 0 && nm > 0) {
    using TI = Dual<double, nb>;
    Interval<Sch, TI> q = iv.template cast<TI>();
    for (int a = 0; a < nb; ++a) q.w(a) = TI::variable(iv.w(a), a);
    TI L0;
    Vec<TI, nm> C;
    interval_parts(model, q, h, L0, C);
    for (int k = 0; k < nm; ++k)
      for (int i = 0; i < nb; ++i) D(i, k) = C(k).d[i] / h;
  }
  (void)model, (void)iv, (void)h;
  return D;
}

// node_residual(nullptr, &right) and aux_residual(right) in one evaluation: the node's
// perturbation (directions 0..nv-1) and the bubbles (nv..nv+nb-1) seeded together in one dual,
// the multiplier rows read off the same pass's constraint values. One evaluation of the
// group curve's jet instead of three.
template <class Sch>
void right_interval_rows(const typename Sch::Model& model, const Interval<Sch, double>& right, double h,
                         Vec<double, Sch::variation>& E, Vec<double, Sch::aux>& R) {
  constexpr int nv = Sch::variation, nm = multiplier_count<Sch>, nb = Sch::aux - nm;
  using TI = Dual<double, nv + nb>;
  Interval<Sch, TI> l, q;
  perturb_node<Sch, double, TI>(nullptr, &right, h, l, q);
  for (int a = 0; a < nb; ++a) q.w(a) = TI::variable(right.w(a), nv + a);
  TI S;
  Vec<TI, nm> C;
  interval_parts(model, q, h, S, C);
  for (int k = 0; k < nm; ++k) S = S + q.w(Sch::multipliers(0) + k) * C(k);
  for (int i = 0; i < nv; ++i) E(i) = S.d[i] / h;
  for (int i = 0; i < nb; ++i) R(i) = S.d[nv + i] / h;
  for (int k = 0; k < nm; ++k) R(nb + k) = C(k).v / h;
}

// The node after an interval: (x, v, Ω) at its end, and the interval that starts there with
// the given unknowns.
template <class Sch, class T>
Interval<Sch, T> next_interval_base(const Interval<Sch, T>& prev, double h) {
  Interval<Sch, T> n;
  n.x = prev.x_end(h);
  n.v = prev.v_end(h);
  n.Om = prev.Om_end(h);
  return n;
}

}  // namespace lpshoot
