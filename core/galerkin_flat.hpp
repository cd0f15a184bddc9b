// Galerkin step derivatives for problems without a group (d = 0) by the chain rule through the
// jet (issue 9). Without a group the jet at Gauss point i is linear in the interval's smooth
// coordinates y = (x, v, X2, V1, a_1 .. a_{S-3}) (galerkin.hpp, jet_at):
//   q_i = M_i y,  M_i = K_i ⊗ I_r,  K_i = [1  hτ  h²H01  h²H11  h²β_j ;
//                                          0  1   h H01'  h H11'  h β_j' ;
//                                          0  0    H01''   H11''   β_j'']   (at τ_i),
// so with φ_i = ℓ + λ_i · χ (one interval's multipliers λ_i at point i)
//   ∇_y L~ = h Σ b_i M_iᵀ ∇φ_i(q_i),  ∇²_y L~ = h Σ b_i M_iᵀ ∇²φ_i(q_i) M_i,
//   ∂C_{i,c}/∂y = h b_i M_iᵀ ∇χ_c(q_i),
// where ∇φ_i and ∇²φ_i are taken in the jet's 3r directions only (nested duals of width 3r),
// instead of carrying every step direction through the jet and ℓ. The step's equations and
// their derivatives are then linear maps of each interval's gradient and Hessian in (y, λ):
//   F = (A_l ∇L~_{n-1} + A_r ∇L~_n) / h,  ∂F/∂z = A_r ∇²L~_n S_z / h,
//   ∂F/∂state = (A_l ∇²L~_{n-1} + A_r ∇²L~_n S_b) / h,
// with A_l, A_r the node perturbations of perturb_node (and interval n's own rows), S_z the
// placement of the unknowns in interval n and S_b its base node as a function of the state.
// Same equations as the nested-dual evaluation (evaluate_galerkin_step_nested), to roundoff.
#pragma once

#include "galerkin.hpp"

#include <type_traits>

namespace lpshoot {

// One interval's L~ = L0 + λ · C as a function of (y, λ): gradient and Hessian (the (λ, λ)
// block is zero). y: the interval's smooth coordinates in the state's layout (without a group
// x, v, X2, V1, bubbles; with one also Ω, O1 and δ, galerkin_group.hpp).
template <class Sch>
struct IntervalDerivatives {
  static constexpr int r = Sch::r, nm = multiplier_count<Sch>;
  static constexpr int ny = Sch::state - nm;
  static constexpr int ne = ny + nm;
  Vec<double, ne> gradient;                  // (∂L~/∂y, C)
  Eigen::Matrix<double, ne, ne> hessian;     // [[∇²_y L~, ∂C/∂y], [∂C/∂yᵀ, 0]]
};

// K_i of the file comment (3 x (4 + S - 3), scalar columns x, v, X2, V1, bubbles) at Gauss
// point i, and the jet q_i = (K_i ⊗ I_r) y (block by block: K's zeros are skipped).
template <class Sch>
struct FlatJetMap {
  static constexpr int r = Sch::r, cols = 4 + Sch::bubbles;
  Eigen::Matrix<double, 3, cols> K = Eigen::Matrix<double, 3, cols>::Zero();

  FlatJetMap(double h, int i) {
    const auto& tab = GalerkinTable<Sch::degree, Sch::gauss>::get();
    const auto& B = tab.basis[i];
    K(0, 0) = 1, K(0, 1) = h * tab.c[i], K(1, 1) = 1;
    const double scale[3] = {h * h, h, 1.0};  // h^(2-k): the k-th time derivative of h² H(τ)
    for (int f = 0; f < 2 + Sch::bubbles; ++f)  // X2 (H01), V1 (H11), bubbles: basis functions 2, 3, 4 ..
      for (int k = 0; k < 3; ++k) K(k, 2 + f) = B[2 + f][k] * scale[k];
  }
  template <class Y>
  Vec<double, 3 * r> jet(const Y& y) const {
    Vec<double, 3 * r> q = Vec<double, 3 * r>::Zero();
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < cols; ++j)
        if (K(k, j) != 0.0) q.template segment<r>(k * r) += K(k, j) * y.template segment<r>(j * r);
    return q;
  }
};

// An interval's smooth coordinates y = (x, v, X2, V1, bubbles).
template <class Sch>
Vec<double, IntervalDerivatives<Sch>::ny> flat_coordinates_of(const Interval<Sch, double>& iv) {
  constexpr int r = Sch::r, ny = IntervalDerivatives<Sch>::ny;
  Vec<double, ny> y;
  y << iv.x, iv.v, iv.X2, iv.V1, iv.w.template head<ny - 4 * r>();
  return y;
}

// An interval's tangent coordinates without a group, (x, v, X2, V1, bubbles, λ): the state's
// layout (galerkin.hpp offsets) and IntervalDerivatives' (y, λ).
template <class Sch>
Vec<double, Sch::state> flat_interval_coordinates(const Interval<Sch, double>& iv) {
  static_assert(Sch::d == 0 && IntervalDerivatives<Sch>::ne == Sch::state, "plain coordinates only without a group");
  Vec<double, Sch::state> c;
  c.template segment<Sch::r>(Sch::x_off) = iv.x;
  c.template segment<Sch::r>(Sch::v_off) = iv.v;
  c.template segment<Sch::r>(Sch::X2_off) = iv.X2;
  c.template segment<Sch::r>(Sch::V1_off) = iv.V1;
  c.template segment<Sch::aux>(Sch::aux_off) = iv.w;
  return c;
}

// IntervalDerivatives' gradient alone, (∂L~/∂y, C): first derivatives of φ_i in the jet's
// 3r directions, pushed through K_i (what a step's residual needs; no Hessian).
template <class Sch>
Vec<double, IntervalDerivatives<Sch>::ne> flat_interval_gradient(const typename Sch::Model& model,
                                                                    const Interval<Sch, double>& iv, double h) {
  static_assert(Sch::d == 0, "the jet is linear in the interval's coordinates only without a group");
  using D = IntervalDerivatives<Sch>;
  constexpr int r = Sch::r, m = Sch::m, ny = D::ny, nq = 3 * r, cols = FlatJetMap<Sch>::cols;
  using T1 = Dual<double, nq>;
  const auto& tab = GalerkinTable<Sch::degree, Sch::gauss>::get();
  const Vec<double, ny> y = flat_coordinates_of(iv);
  Vec<double, D::ne> out = Vec<double, D::ne>::Zero();
  Jet<typename Sch::Model, T1> q;  // constructed (zeroed) once: every entry is set at each point
  for (int i = 0; i < Sch::gauss; ++i) {
    const double w = h * tab.b[i];
    const FlatJetMap<Sch> K(h, i);
    const Vec<double, nq> qv = K.jet(y);
    for (int a = 0; a < r; ++a)
      q.p(a) = T1::variable(qv(a), a), q.dp(a) = T1::variable(qv(r + a), r + a),
      q.ddp(a) = T1::variable(qv(2 * r + a), 2 * r + a);
    T1 phi = model.template lagrangian<T1>(q);
    if constexpr (m > 0) {
      const Vec<T1, m> chi = model.template constraints<T1>(q);
      for (int c = 0; c < m; ++c) {
        phi = phi + iv.w(Sch::multipliers(i) + c) * chi(c);
        out(ny + i * m + c) = w * chi(c).v;
      }
    }
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < cols; ++j)
        if (K.K(k, j) != 0.0)
          for (int a = 0; a < r; ++a) out(j * r + a) += (w * K.K(k, j)) * phi.d[k * r + a];
  }
  return out;
}

template <class Sch>
IntervalDerivatives<Sch> flat_interval_derivatives(const typename Sch::Model& model,
                                                       const Interval<Sch, double>& iv, double h) {
  static_assert(Sch::d == 0, "the jet is linear in the interval's coordinates only without a group");
  using C = typename Sch::Model;
  using D = IntervalDerivatives<Sch>;
  constexpr int r = Sch::r, m = Sch::m, nb = Sch::bubbles, ny = D::ny, ne = D::ne, nm = D::nm, nq = 3 * r;
  constexpr int cols = 4 + nb;  // x, v, X2, V1, bubbles (scalar columns of K)
  using T1 = Dual<double, nq>;
  using T2 = Dual<T1, nq>;
  const auto& tab = GalerkinTable<Sch::degree, Sch::gauss>::get();

  const Vec<double, ny> y = flat_coordinates_of(iv);
  D out;
  out.gradient.setZero();
  out.hessian.setZero();
  for (int i = 0; i < Sch::gauss; ++i) {
    const double w = h * tab.b[i];
    const FlatJetMap<Sch> K(h, i);
    const Vec<double, nq> qv = K.jet(y);

    // φ = ℓ + λ_i · χ on the jet, every jet coordinate seeded at both dual levels.
    Jet<C, T2> q;
    auto seed = [&](int k) {
      T2 s(T1::variable(qv(k), k));
      s.d[k] = T1(1.0);
      return s;
    };
    for (int a = 0; a < r; ++a) q.p(a) = seed(a), q.dp(a) = seed(r + a), q.ddp(a) = seed(2 * r + a);
    T2 phi = model.template lagrangian<T2>(q);
    Eigen::Matrix<double, nq, (m > 0 ? m : 1)> chi_grad;
    if constexpr (m > 0) {
      const Vec<T2, m> chi = model.template constraints<T2>(q);
      for (int c = 0; c < m; ++c) {
        const double lambda = iv.w(Sch::multipliers(i) + c);
        phi = phi + lambda * chi(c);
        out.gradient(ny + i * m + c) = w * chi(c).v.v;
        for (int k = 0; k < nq; ++k) chi_grad(k, c) = chi(c).v.d[k];
      }
    }
    Vec<double, nq> g;
    Eigen::Matrix<double, nq, nq> H;
    for (int k = 0; k < nq; ++k) {
      g(k) = phi.v.d[k];
      for (int l = 0; l < nq; ++l) H(k, l) = phi.d[k].d[l];
    }
    // Mᵀ g, Mᵀ H M and Mᵀ ∇χ with M = K ⊗ I_r.
    Eigen::Matrix<double, nq, ny> HM = Eigen::Matrix<double, nq, ny>::Zero();
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < cols; ++j) {
        if (K.K(k, j) == 0.0) continue;
        const double kj = K.K(k, j);
        out.gradient.template segment<r>(j * r) += (w * kj) * g.template segment<r>(k * r);
        HM.template middleCols<r>(j * r) += kj * H.template middleCols<r>(k * r);
        if constexpr (m > 0)
          out.hessian.template block<r, m>(j * r, ny + i * m) += (w * kj) * chi_grad.template middleRows<r>(k * r);
      }
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < cols; ++j)
        if (K.K(k, j) != 0.0)
          out.hessian.template block<r, ny>(j * r, 0) += (w * K.K(k, j)) * HM.template middleRows<r>(k * r);
  }
  if constexpr (m > 0)  // the (λ, y) block
    out.hessian.template bottomLeftCorner<nm, ny>() = out.hessian.template topRightCorner<ny, nm>().transpose();
  (void)ne;
  return out;
}

// The maps of the file comment. Rows: the node equations E (2r), interval n's bubble rows, its
// multiplier rows (= the unknowns' layout without a group).
template <class Sch>
struct FlatStepMaps {
  using D = IntervalDerivatives<Sch>;
  static constexpr int r = Sch::r, ny = D::ny, ne = D::ne, nz = Sch::unknowns, ns = Sch::state;
  Eigen::Matrix<double, nz, ne> left, right;  // A_l, A_r
  Eigen::Matrix<double, ne, nz> unknowns;     // S_z
  Eigen::Matrix<double, ne, ns> base;         // S_b

  explicit FlatStepMaps(double h) {
    constexpr int x = 0, v = r, X2 = 2 * r, V1 = 3 * r;
    left.setZero(), right.setZero(), unknowns.setZero(), base.setZero();
    for (int a = 0; a < r; ++a) {
      // Node n is the end of interval n-1 (X2 += e_x, V1 += e_v) and the base of interval n
      // (x += h² e_x, v += h e_v, X2 -= e_x + e_v, V1 -= e_v); rows are ∂L~/∂e.
      left(a, X2 + a) = 1, left(r + a, V1 + a) = 1;
      right(a, x + a) = h * h, right(a, X2 + a) = -1;
      right(r + a, v + a) = h, right(r + a, X2 + a) = -1, right(r + a, V1 + a) = -1;
      // Interval n's base node: x + h v + h² X2 and v + h V1 of the state.
      base(x + a, x + a) = 1, base(x + a, v + a) = h, base(x + a, X2 + a) = h * h;
      base(v + a, v + a) = 1, base(v + a, V1 + a) = h;
    }
    // Interval n's own rows: ∂L~/∂a (bubbles, y indices 4r ..) and C (the λ entries).
    for (int k = 0; k < ne - 4 * r; ++k) right(2 * r + k, 4 * r + k) = 1;
    // The unknowns (X2, V1, bubbles, λ) are interval n's coordinates from 2r on.
    for (int k = 0; k < nz; ++k) unknowns(2 * r + k, k) = 1;
  }
};

// A_l g / h and A_r g / h for one interval's gradient g = (∂L~/∂y, C) (FlatStepMaps, written
// out): the state's part of E_n, and interval n's part of E_n with its own rows.
template <class Sch>
Vec<double, Sch::variation> flat_left_rows(const Vec<double, IntervalDerivatives<Sch>::ne>& g, double h) {
  constexpr int r = Sch::r;
  Vec<double, Sch::variation> E;
  E << g.template segment<r>(2 * r) / h, g.template segment<r>(3 * r) / h;
  return E;
}

template <class Sch>
Vec<double, Sch::unknowns> flat_right_rows(const Vec<double, IntervalDerivatives<Sch>::ne>& g, double h) {
  constexpr int r = Sch::r, ne = IntervalDerivatives<Sch>::ne;
  const auto gx = g.template segment<r>(0), gv = g.template segment<r>(r);
  const auto gX2 = g.template segment<r>(2 * r), gV1 = g.template segment<r>(3 * r);
  Vec<double, Sch::unknowns> F;
  F.template segment<r>(0) = h * gx - gX2 / h;
  F.template segment<r>(r) = gv - (gX2 + gV1) / h;
  F.template tail<ne - 4 * r>() = g.template tail<ne - 4 * r>() / h;
  return F;
}

// A flow's step-to-step carry: interval n's derivatives at its solution are interval n's as the
// state of step n + 1 (galerkin_group.hpp with a group).
template <class Sch>
struct StepCarry {
  bool valid = false;
  IntervalDerivatives<Sch> interval{};
};

// ∂F/∂z and, when NO > nz, the state's columns ∂F/∂state (file comment) from interval n's Hessian
// and, if given, the state's (without it the state's columns hold interval n's part alone).
template <class Sch, int NO>
void flat_step_jacobian(const FlatStepMaps<Sch>& maps, double h,
                        const Eigen::Matrix<double, FlatStepMaps<Sch>::ne, FlatStepMaps<Sch>::ne>& right_hessian,
                        const Eigen::Matrix<double, FlatStepMaps<Sch>::ne, FlatStepMaps<Sch>::ne>* left_hessian,
                        Eigen::Matrix<double, Sch::unknowns, NO>& J) {
  constexpr int nz = Sch::unknowns;
  const double inv_h = 1.0 / h;
  const Eigen::Matrix<double, nz, FlatStepMaps<Sch>::ne> AH = inv_h * (maps.right * right_hessian);
  J.template leftCols<nz>().noalias() = AH * maps.unknowns;
  if constexpr (NO != nz) {
    J.template rightCols<NO - nz>().noalias() = AH * maps.base;
    if (left_hessian) J.template rightCols<NO - nz>().noalias() += inv_h * (maps.left * *left_hessian);
  } else {
    (void)left_hessian;
  }
}

// evaluate_galerkin_step (galerkin_step.hpp) for d = 0: same arguments and results. `carry`, when
// valid, holds the state's derivatives; on return it holds interval n's.
template <class Sch, int NO>
void evaluate_galerkin_step_flat(const typename Sch::Model& model, double h, const Interval<Sch, double>& state,
                                 const Interval<Sch, double>& z, bool with_state,
                                 const Vec<double, Sch::variation>* fixed, Vec<double, Sch::unknowns>& F,
                                 Eigen::Matrix<double, Sch::unknowns, NO>& J, StepCarry<Sch>* carry = nullptr) {
  constexpr int nv = Sch::variation;
  const FlatStepMaps<Sch> maps(h);
  Interval<Sch, double> right = z;
  const Interval<Sch, double> b = next_interval_base(state, h);
  right.x = b.x, right.v = b.v;
  const IntervalDerivatives<Sch> dr = flat_interval_derivatives<Sch>(model, right, h);
  const double inv_h = 1.0 / h;
  F.noalias() = inv_h * (maps.right * dr.gradient);
  if (fixed) {
    flat_step_jacobian<Sch, NO>(maps, h, dr.hessian, nullptr, J);
    F.template head<nv>() += *fixed;
  } else {
    const IntervalDerivatives<Sch> dl =
        carry && carry->valid ? carry->interval : flat_interval_derivatives<Sch>(model, state, h);
    F.noalias() += inv_h * (maps.left * dl.gradient);
    flat_step_jacobian<Sch, NO>(maps, h, dr.hessian, with_state ? &dl.hessian : nullptr, J);
  }
  if (carry) {
    carry->interval = dr;
    carry->valid = true;
  }
}

}  // namespace lpshoot
