// Galerkin step derivatives with a group (d > 0) from each interval's gradient and Hessian
// (issue 9): the counterpart of galerkin_flat.hpp, for a step's sensitivity.
//
// An interval's coordinates y = (x, v, Ω, X2, V1, O1, δ, bubbles) (the state's layout, W moved
// to W exp(h δ)) and its multipliers λ. L~ with its gradient and Hessian in y
// (galerkin_group_interval.hpp) replaces two evaluations in nested duals per step (interval n in
// its unknowns and base node, interval n-1 in its coordinates, each against the 2r + 2d node
// perturbations). Each interval's derivatives are computed once, at its solution, and carried to
// the next step, where it is the state.
//
// The node perturbation e = (e_x, e_v, e_Ω, η) of galerkin.hpp (perturb_node) moves interval
// n-1 to W exp(h δ) exp(h η) and interval n to exp(-h η) W = W exp(-h Ad_{W^{-1}} η); the
// other coordinates move linearly. With B(u, w) = ∂L~/∂δ · [u, w] and the Baker–Campbell–
// Hausdorff formula exp(hX) exp(hY) = exp(h (X + Y + (h/2) [X, Y] + O(h²))):
//   E_n        = (A_l ∇L~_{n-1} + A_r(W_n) ∇L~_n) / h,
//   ∂E_n/∂z     = A_r ∇²L~_n S_z / h  − ½ Ad_{W_n^{-1}}ᵀ B_n          (η rows, ζ columns),
//   ∂E_n/∂state = (A_l ∇²L~_{n-1} + A_r ∇²L~_n S_b) / h + ½ B_{n-1}ᵀ  (η rows, δ columns),
// with A_l, A_r the perturbations' maps (A_r's η block −Ad_{W_n^{-1}}ᵀ), S_z the placement of
// the unknowns in interval n (ζ as δ) and S_b interval n's base node as a function of the state.
// Same equations as evaluate_galerkin_step_nested, to roundoff (tests/test_galerkin_group.cpp).
#pragma once

#include "galerkin.hpp"
#include "galerkin_flat.hpp"
#include "galerkin_group_interval.hpp"

namespace lpshoot {

// B(u, w) = g · [u, w] on the basis of the algebra: B(i, j) = g · [e_i, e_j], from
// [X, Y] = d/dt Ad_{exp(tX)} Y at t = 0.
template <class G>
Eigen::Matrix<double, G::dim, G::dim> bracket_form(const Vec<double, G::dim>& g) {
  constexpr int d = G::dim;
  using T = Dual<double, 1>;
  Eigen::Matrix<double, d, d> B;
  for (int i = 0; i < d; ++i) {
    typename G::template Tangent<T> t = G::template Tangent<T>::Constant(T(0.0));
    t(i) = T::variable(0.0, 0);
    const Eigen::Matrix<T, d, d> Ad = G::Ad(G::template exp<T>(t));
    for (int j = 0; j < d; ++j) {
      double s = 0;
      for (int c = 0; c < d; ++c) s += g(c) * Ad(c, j).d[0];
      B(i, j) = s;
    }
  }
  return B;
}

// A_l g / h: the state's part of E_n from its gradient g.
template <class Sch>
Vec<double, Sch::variation> group_left_rows(const Vec<double, IntervalDerivatives<Sch>::ne>& g, double h) {
  constexpr int r = Sch::r, d = Sch::d;
  Vec<double, Sch::variation> E;
  E << g.template segment<r>(Sch::X2_off) / h, g.template segment<r>(Sch::V1_off) / h,
      g.template segment<d>(Sch::O1_off) / h, g.template segment<d>(Sch::W_off) / h;
  return E;
}

// A_r M for an interval with group increment W, Ad = Ad_{W^{-1}}: A_r has rows E (the node at
// the interval's base, perturbed as in perturb_node), then the interval's own rows (∂L~/∂bubbles,
// C), and columns the interval's coordinates (state layout), the rows of M. It has 2 or 3
// non-zeros per row but its η block, −Adᵀ; applied by rows, never formed.
template <class Sch, int C>
Eigen::Matrix<double, Sch::unknowns, C> group_right_map_times(double h, const Eigen::Matrix<double, Sch::d, Sch::d>& Ad,
                                                              const Eigen::Matrix<double, IntervalDerivatives<Sch>::ne, C>& M) {
  constexpr int r = Sch::r, d = Sch::d, nz = Sch::unknowns, nv = Sch::variation;
  constexpr int eta = 2 * r + d;
  Eigen::Matrix<double, nz, C> out;
  for (int a = 0; a < r; ++a) {
    out.row(a) = (h * h) * M.row(Sch::x_off + a) - M.row(Sch::X2_off + a);
    out.row(r + a) = h * M.row(Sch::v_off + a) - M.row(Sch::X2_off + a) - M.row(Sch::V1_off + a);
  }
  for (int a = 0; a < d; ++a) out.row(2 * r + a) = h * M.row(Sch::Om_off + a) - M.row(Sch::O1_off + a);
  out.template middleRows<d>(eta).noalias() = -Ad.transpose() * M.template middleRows<d>(Sch::W_off);
  out.template bottomRows<nz - nv>() = M.template middleRows<nz - nv>(Sch::aux_off);
  return out;
}

// F and J of the step (evaluate_galerkin_step's contract): from interval n's derivatives at z
// and, for the state's columns (NO = unknowns + state) or without `fixed` (the state's part of
// E_n), the state's (`carry`, when valid; computed otherwise). With `carry`, on return it holds
// interval n's.
template <class Sch, int NO>
void evaluate_galerkin_step_group(const typename Sch::Model& model, double h, const Interval<Sch, double>& state,
                                  const Interval<Sch, double>& z, const Vec<double, Sch::variation>* fixed,
                                  Vec<double, Sch::unknowns>& F, Eigen::Matrix<double, Sch::unknowns, NO>& J,
                                  StepCarry<Sch>* carry) {
  using G = typename Sch::Group;
  using D = IntervalDerivatives<Sch>;
  constexpr int r = Sch::r, d = Sch::d, nz = Sch::unknowns, ns = Sch::state, nv = Sch::variation, ne = D::ne;
  constexpr int eta = 2 * r + d;  // first η row
  constexpr bool state_cols = NO == nz + ns;
  static_assert(NO == nz || state_cols, "columns: the unknowns, or the unknowns and the state");
  static_assert(ne == ns, "an interval's derivatives are in the state's layout");

  Interval<Sch, double> right = z;
  const Interval<Sch, double> base = next_interval_base(state, h);
  right.x = base.x, right.v = base.v, right.Om = base.Om;
  const D dr = group_interval_derivatives<Sch>(model, right, h);

  const Eigen::Matrix<double, d, d> Ad = G::Ad(G::inverse(z.W));  // Ad_{W_n^{-1}}: A_r's η block is −Adᵀ
  const Eigen::Matrix<double, d, d> At = Ad.transpose();

  const double inv_h = 1.0 / h;
  F.noalias() = inv_h * group_right_map_times<Sch, 1>(h, Ad, dr.gradient);
  const Eigen::Matrix<double, nz, ne> ArH = inv_h * group_right_map_times<Sch, ne>(h, Ad, dr.hessian);
  // The unknowns are interval n's coordinates from X2 on (ζ as δ); the group's term (file comment).
  J.template leftCols<nz>() = ArH.template rightCols<nz>();
  const Eigen::Matrix<double, d, d> Br = bracket_form<G>(dr.gradient.template segment<d>(Sch::W_off));
  J.template block<d, d>(eta, Sch::W_off - Sch::node) -= 0.5 * (At * Br);

  if (fixed && !state_cols) {
    F.template head<nv>() += *fixed;
  } else {
    const D dl = carry && carry->valid ? carry->interval : group_interval_derivatives<Sch>(model, state, h);
    F.template head<nv>() += group_left_rows<Sch>(dl.gradient, h);
    if constexpr (state_cols) {
      // A_l ∇²L~_{n-1} / h: rows X2, V1, O1 and δ of the state's Hessian (A_l picks them).
      J.template rightCols<ns>().setZero();
      J.template block<r, ns>(0, nz) = inv_h * dl.hessian.template middleRows<r>(Sch::X2_off);
      J.template block<r, ns>(r, nz) = inv_h * dl.hessian.template middleRows<r>(Sch::V1_off);
      J.template block<d, ns>(2 * r, nz) = inv_h * dl.hessian.template middleRows<d>(Sch::O1_off);
      J.template block<d, ns>(eta, nz) = inv_h * dl.hessian.template middleRows<d>(Sch::W_off);
      const Eigen::Matrix<double, d, d> Bl = bracket_form<G>(dl.gradient.template segment<d>(Sch::W_off));
      J.template block<d, d>(eta, nz + Sch::W_off) += 0.5 * Bl.transpose();
      // Interval n through its base node (x + h v + h² X2, v + h V1, Ω + h O1 of the state).
      for (int a = 0; a < r; ++a) {
        J.col(nz + Sch::x_off + a) += ArH.col(Sch::x_off + a);
        J.col(nz + Sch::v_off + a) += h * ArH.col(Sch::x_off + a) + ArH.col(Sch::v_off + a);
        J.col(nz + Sch::X2_off + a) += (h * h) * ArH.col(Sch::x_off + a);
        J.col(nz + Sch::V1_off + a) += h * ArH.col(Sch::v_off + a);
      }
      for (int a = 0; a < d; ++a) {
        J.col(nz + Sch::Om_off + a) += ArH.col(Sch::Om_off + a);
        J.col(nz + Sch::O1_off + a) += h * ArH.col(Sch::Om_off + a);
      }
    }
  }
  if (carry) {
    carry->interval = dr;
    carry->valid = true;
  }
}

}  // namespace lpshoot
