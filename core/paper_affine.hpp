// Affine paper-scheme flows without a group (degree.hpp: L_d quadratic and χ_d affine, d = 0):
// the steps after the first, from the constant window Hessian.
//
// Without a group a window's coordinates x = (p_n .. p_{n+k}, λ^n) enter L~ = L_d + λ·χ_d
// directly, so for such a problem every window's gradient is
//   g(x) = g(x_ref) + H (x - x_ref)
// exactly, with the one Hessian H that all windows share (L_d and χ_d depend on the window and h
// alone) and any reference window x_ref. Step n's residual (step.hpp) is then E_n = Σ_j g_j's
// entries of node n over the windows a_{n-k} .. a_n and χ_d(a_n) = g_n's λ entries: the carried
// gradients of a_{n-k} .. a_{n-1} and H times a vector for a_n, instead of the user's L_d and χ_d
// in duals for every window at every step (electron: ~70% of an affine flow's step).
// Not for problems that keep their nodes' low parts (PaperWindows): they form the nodes'
// differences to their own precision, which H (x - x_ref) would not (paper_windows.hpp).
#pragma once

#include "newton.hpp"
#include "step_solve.hpp"

namespace lpshoot {

// The window gradient of an affine problem without a group, from one window's Hessian, in the
// window's difference coordinates y = (p_0, Δp_0, Δ²p_0, .., Δ^k p_0, λ) (p_i = Σ_j C(i, j) Δ^j p_0):
//   g(x) = g(x_ref) + (H T) (y - y_ref),   x = T y.
// H (x - x_ref) would round each product H_ij (x_j - x_ref,j) ~ |H| |x| before they cancel (the
// electron: ~10 units in the last place of the step's node, against ~1 for the problem's own L_d,
// which differences its nodes first, exactly for nearby nodes); in y the large columns of H T
// (those of the highest differences, ~1/h³ for the electron) meet small differences.
template <class P>
struct AffineWindowGradient {
  static constexpr int k = P::order, r = P::shape_dim, m = P::num_constraints, nw = window_coordinates<P>();
  static_assert(P::Group::dim == 0 && !keeps_low_parts<P>(), "see the file comment");
  Vec<double, nw> gradient;                // g(x_ref)
  Eigen::Matrix<double, nw, nw> in_differences;  // H T
  Vec<double, nw> at;                      // y_ref

  // The window's difference coordinates: nodes p[0..k] (and λ).
  static Vec<double, nw> differences(std::array<Vec<double, r>, k + 1> p, const Vec<double, m>& lam) {
    Vec<double, nw> y;
    for (int j = 0; j <= k; ++j) {
      y.template segment<r>(j * r) = p[0];
      for (int i = 0; i + j < k; ++i) p[i] = p[i + 1] - p[i];  // p[i] <- Δ^{j+1} p_i
    }
    if constexpr (m > 0) y.template tail<m>() = lam;
    return y;
  }
  // Window a_n of step n's block (state s, unknowns z), its nodes.
  static std::array<Vec<double, r>, k + 1> nodes(const FlowState<P>& s, const StepUnknowns<P>& z) {
    std::array<Vec<double, r>, k + 1> p;
    for (int i = 0; i < k; ++i) p[i] = s.p[k + i];
    p[k] = z.p;
    return p;
  }

  // Window a_n of step n's block as the reference, with its gradient and Hessian `wh`.
  void set(const WindowHessian<P>& wh, const FlowState<P>& s, const StepUnknowns<P>& z) {
    gradient = wh.gradient;
    Eigen::Matrix<double, nw, nw> T = Eigen::Matrix<double, nw, nw>::Zero();
    for (int i = 0; i <= k; ++i) {
      double binomial = 1;  // C(i, j)
      for (int j = 0; j <= i; ++j) {
        T.template block<r, r>(i * r, j * r) = binomial * Eigen::Matrix<double, r, r>::Identity();
        binomial = binomial * (i - j) / (j + 1);
      }
    }
    if constexpr (m > 0) T.template bottomRightCorner<m, m>().setIdentity();
    in_differences = wh.hessian * T;
    at = differences(nodes(s, z), z.lam);
  }
  // g of window a_n of step n's block.
  Vec<double, nw> of(const FlowState<P>& s, const StepUnknowns<P>& z) const {
    return gradient + in_differences * (differences(nodes(s, z), z.lam) - at);
  }
};

// Step n of an affine flow without a group from the extrapolated predictor and one Newton
// correction on the flow's factored matrix (`chord`, the affine equations' own): F at the
// prediction from the carried gradients of windows a_{n-k} .. a_{n-1} and a_n's from `gradient`,
// then z <- z - J⁻¹ F; after it z solves the step's equations to their rounding. On return the
// carry holds window a_n's gradient at z. As
// newton_solve's affine case: one residual, one correction, no convergence test, a non-finite
// residual reported as such.
template <class P>
StepReport solve_mapped_affine_paper_step(const AffineWindowGradient<P>& gradient,
                                          const ChordMatrix<Dims<P>::unknowns>& chord, const FlowState<P>& s, long n,
                                          StepUnknowns<P>& z, WindowHessianCarry<P>& carry) {
  using D = Dims<P>;
  constexpr int k = D::k, r = D::r, m = D::m, nz = D::unknowns, nw = window_coordinates<P>();
  StepReport rep;
  rep.step = static_cast<int>(n);
  rep.iterations = 1;
  rep.condition = chord.condition;
  step_predictor(s, true, z);
  const Vec<double, nw> g = gradient.of(s, z);
  Vec<double, nz> F;
  F.template head<r>() = g.template head<r>();
  for (int j = 0; j < k; ++j) F.template head<r>() += carry.of(n - k + j).gradient.template segment<r>((k - j) * r);
  if constexpr (m > 0) F.template tail<m>() = g.template tail<m>();
  if (!all_finite(F.data(), nz)) return non_finite_step(rep, static_cast<int>(n));
  rep.residual = F.template lpNorm<Eigen::Infinity>();
  const Vec<double, nz> dz = chord.lu.solve(-F);
  apply_correction(z, dz);
  // At z as stored: g at the prediction plus H times the correction would be the gradient at the
  // correction before its rounding to z (the electron: ~1 unit in the last place more per step).
  WindowHessian<P>& slot = carry.of(n);
  slot.gradient = gradient.of(s, z);
  slot.index = n;
  rep.status = StepStatus::Converged;
  return rep;
}

}  // namespace lpshoot
