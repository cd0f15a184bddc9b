// The rows of an end node that come from the action, with their derivatives, from the end
// interval's gradient g and Hessian H (galerkin_flat.hpp, galerkin_group.hpp), for shooting's
// boundary Jacobian (issue 9): one evaluation of the interval's derivatives instead of nested
// duals over its whole tangent and the node perturbations.
//
// At the initial node the interval is the node's right one: the rows are the node equations E
// (perturb_node without a left interval: the natural boundary conditions) and the interval's own
// equations (bubbles, constraints at its Gauss points), R = A_r g / h. At the terminal node it is
// the node's left one, R = E = A_l g / h. In the interval's tangent coordinates y (state layout,
// W exp(h δ)), ∂R/∂y = A H / h plus, with a group, the bracket terms of galerkin_group.hpp on the
// (η, δ) block: −½ Ad_{W^{-1}}ᵀ B at the initial node, +½ Bᵀ at the terminal one, with
// B = bracket_form(∂L~/∂δ).
#pragma once

#include "galerkin_flat.hpp"
#include "galerkin_group.hpp"

namespace lpshoot {

// R and ∂R/∂y as above; returns the number of rows (the unknowns' count at the initial node,
// the node variation's at the terminal one; the rest of R and J are zero).
template <class Sch>
int galerkin_end_rows(const typename Sch::Model& model, const Interval<Sch, double>& iv, double h, bool initial,
                      Vec<double, Sch::unknowns>& R, Eigen::Matrix<double, Sch::unknowns, Sch::state>& J) {
  using G = typename Sch::Group;
  using D = IntervalDerivatives<Sch>;
  constexpr int r = Sch::r, d = Sch::d, nz = Sch::unknowns, nv = Sch::variation, ne = D::ne;
  static_assert(ne == Sch::state, "an interval's derivatives are in the state's layout");
  const double inv_h = 1.0 / h;
  R.setZero();
  J.setZero();
  if constexpr (d == 0) {
    const D dv = flat_interval_derivatives<Sch>(model, iv, h);
    const FlatStepMaps<Sch> maps(h);
    const Eigen::Matrix<double, nz, ne>& A = initial ? maps.right : maps.left;
    R.noalias() = inv_h * (A * dv.gradient);
    J.noalias() = inv_h * (A * dv.hessian);
  } else {
    constexpr int eta = 2 * r + d;  // first η row
    const D dv = group_interval_derivatives<Sch>(model, iv, h);
    const Eigen::Matrix<double, d, d> B = bracket_form<G>(dv.gradient.template segment<d>(Sch::W_off));
    if (initial) {
      const Eigen::Matrix<double, d, d> Ad = G::Ad(G::inverse(iv.W));
      R.noalias() = inv_h * group_right_map_times<Sch, 1>(h, Ad, dv.gradient);
      J.noalias() = inv_h * group_right_map_times<Sch, ne>(h, Ad, dv.hessian);
      J.template block<d, d>(eta, Sch::W_off) -= 0.5 * (Ad.transpose() * B);
    } else {  // A_l picks the rows X2, V1, O1 and δ
      R.template head<nv>() = group_left_rows<Sch>(dv.gradient, h);
      J.template middleRows<r>(0) = inv_h * dv.hessian.template middleRows<r>(Sch::X2_off);
      J.template middleRows<r>(r) = inv_h * dv.hessian.template middleRows<r>(Sch::V1_off);
      J.template middleRows<d>(2 * r) = inv_h * dv.hessian.template middleRows<d>(Sch::O1_off);
      J.template middleRows<d>(eta) = inv_h * dv.hessian.template middleRows<d>(Sch::W_off);
      J.template block<d, d>(eta, Sch::W_off) += 0.5 * B.transpose();
    }
  }
  return initial ? nz : nv;
}

}  // namespace lpshoot
