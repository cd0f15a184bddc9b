// One step of the discrete flow map (METHOD.md §3, paper Propositions 1–2).
//
// Step n (n >= k) solves F(z) = (E_n, chi_d(a_n)) = 0 for z = (p_{n+k}, ζ, λ^n), where
// g~_{n+k-1} = ĝ exp(ζ) around the current iterate ĝ (re-centred after every update, so the
// derivatives are always taken at ζ = 0). ∂F/∂z is the matrix of Proposition 2; its condition
// number is the regularity diagnostic. Sensitivities follow from the implicit function theorem:
// dz = -(∂F/∂z)^{-1} (∂F/∂state) d(state).
#pragma once

#include "local_action.hpp"

#include <Eigen/LU>

#include <cstdio>
#include <limits>
#include <string>

namespace lpshoot {

// The data one step needs: nodes n-k .. n+k-1, increments g~_{n-k} .. g~_{n+k-2} and
// multipliers λ^{n-k} .. λ^{n-1}. Before the first step (n = k) it is the flow's initial data
// p_0 .. p_{2k-1}, g~_0 .. g~_{2k-2}, λ^0 .. λ^{k-1}. Its tangent coordinates (size
// Dims<P>::state) are δp for each node, δ with g~ -> g~ exp(δ) for each increment, δλ.
template <class P>
struct FlowState {
  static constexpr int k = P::order;
  std::array<Vec<double, P::shape_dim>, 2 * k> p;
  std::array<GroupElement<P, double>, 2 * k - 1> g;
  std::array<Vec<double, P::num_constraints>, k> lam;

  static constexpr int p_offset(int i) { return i * P::shape_dim; }
  static constexpr int g_offset(int i) { return 2 * k * P::shape_dim + i * P::Group::dim; }
  static constexpr int lam_offset(int j) {
    return 2 * k * P::shape_dim + (2 * k - 1) * P::Group::dim + j * P::num_constraints;
  }
};

// What one step solves for.
template <class P>
struct StepUnknowns {
  Vec<double, P::shape_dim> p;      // p_{n+k}
  GroupElement<P, double> g;        // g~_{n+k-1}
  Vec<double, P::num_constraints> lam;  // λ^n
};

enum class StepStatus { Converged, NotConverged, Singular, NonFinite };

struct StepReport {
  int step = -1;  // n
  StepStatus status = StepStatus::NotConverged;
  int iterations = 0;
  double residual = 0;   // max-norm of F at the last evaluation
  double condition = 0;  // 1-norm condition number of ∂F/∂z at the last evaluation
  std::string message;   // empty when converged
};

struct NewtonOptions {
  int max_iterations = 20;
  // Converged when every Newton correction satisfies |dz_i| <= step_tolerance * (1 + |z_i|).
  double step_tolerance = 1e-12;
  // A step whose ∂F/∂z has a larger condition estimate is reported singular.
  double max_condition = 1e13;
};

// Evaluates F and its derivatives at (state, z). Derivative columns: the nz unknowns, then (if
// with_state) the state's tangent coordinates.
template <class P, int NO>
void evaluate_step(const P& problem, double h, const FlowState<P>& s, const StepUnknowns<P>& z,
                   bool with_state, Vec<double, Dims<P>::unknowns>& F,
                   Eigen::Matrix<double, Dims<P>::unknowns, NO>& J) {
  using D = Dims<P>;
  using G = typename P::Group;
  using T = Dual<double, NO>;
  constexpr int k = D::k, nz = D::unknowns;
  auto seeded = [](double x, int col) { return T::variable(x, col); };

  NodeBlock<P, T> b;
  for (int i = 0; i < 2 * k; ++i)
    for (int a = 0; a < D::r; ++a)
      b.p[i](a) = with_state ? seeded(s.p[i](a), nz + FlowState<P>::p_offset(i) + a) : T(s.p[i](a));
  for (int a = 0; a < D::r; ++a) b.p[2 * k](a) = seeded(z.p(a), a);
  for (int i = 0; i < 2 * k - 1; ++i) {
    b.g[i] = G::template cast<T>(s.g[i]);
    if (with_state) {
      typename G::template Tangent<T> delta;
      for (int a = 0; a < D::d; ++a) delta(a) = seeded(0.0, nz + FlowState<P>::g_offset(i) + a);
      b.g[i] = G::compose(b.g[i], G::template exp<T>(delta));
    }
  }
  typename G::template Tangent<T> zeta;
  for (int a = 0; a < D::d; ++a) zeta(a) = seeded(0.0, D::r + a);
  b.g[2 * k - 1] = G::compose(G::template cast<T>(z.g), G::template exp<T>(zeta));
  for (int j = 0; j < k; ++j)
    for (int a = 0; a < D::m; ++a)
      b.lam[j](a) = with_state ? seeded(s.lam[j](a), nz + FlowState<P>::lam_offset(j) + a)
                               : T(s.lam[j](a));
  for (int a = 0; a < D::m; ++a) b.lam[k](a) = seeded(z.lam(a), D::r + D::d + a);

  const Vec<T, D::node> E = node_residual(problem, b, k, 0, k, h);
  Vec<T, nz> Fd;
  Fd.template head<D::node>() = E;
  if constexpr (D::m > 0) Fd.template tail<D::m>() = problem.template constraints<T>(b.window(k), h);
  for (int i = 0; i < nz; ++i) {
    F(i) = Fd(i).v;
    for (int c = 0; c < NO; ++c) J(i, c) = Fd(i).d[c];
  }
}

template <class P>
void apply_correction(StepUnknowns<P>& z, const Vec<double, Dims<P>::unknowns>& dz) {
  using D = Dims<P>;
  using G = typename P::Group;
  z.p += dz.template head<D::r>();
  const typename G::template Tangent<double> dzeta = dz.template segment<D::d>(D::r);
  z.g = G::compose(z.g, G::template exp<double>(dzeta));
  z.lam += dz.template tail<D::m>();
}

// Short numeric text for messages ("1.2e+16").
inline std::string format_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// ||J||_1 ||J^{-1}||_1 from the LU factors (exact, cheap at these sizes); inf or NaN if singular.
template <class M, class LU>
double condition_number_1(const M& J, const LU& lu) {
  const M inv = lu.inverse();
  return J.cwiseAbs().colwise().sum().maxCoeff() * inv.cwiseAbs().colwise().sum().maxCoeff();
}

inline bool all_finite(const double* x, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(x[i])) return false;
  return true;
}

// Solves step n by Newton from the predictor (linear extrapolation of p, previous increment and
// multiplier). No allocation in the loop (everything is fixed size) except the failure message.
template <class P>
StepReport solve_step(const P& problem, double h, const FlowState<P>& s, int n,
                      const NewtonOptions& opt, StepUnknowns<P>& z) {
  using D = Dims<P>;
  constexpr int k = D::k, nz = D::unknowns;
  z.p = 2.0 * s.p[2 * k - 1] - s.p[2 * k - 2];
  z.g = s.g[2 * k - 2];
  if constexpr (D::m > 0) z.lam = s.lam[k - 1];

  StepReport rep;
  rep.step = n;
  Vec<double, nz> F;
  Eigen::Matrix<double, nz, nz> J;
  Eigen::PartialPivLU<Eigen::Matrix<double, nz, nz>> lu;
  auto fail = [&](StepStatus st, const std::string& why) {
    rep.status = st;
    rep.message = "step n=" + std::to_string(n) + ": " + why;
    return rep;
  };
  for (int it = 1; it <= opt.max_iterations; ++it) {
    evaluate_step<P, nz>(problem, h, s, z, false, F, J);
    rep.iterations = it;
    if (!all_finite(F.data(), nz) || !all_finite(J.data(), nz * nz))
      return fail(StepStatus::NonFinite, "the step equations evaluated to a non-finite number");
    rep.residual = F.template lpNorm<Eigen::Infinity>();
    lu.compute(J);
    rep.condition = condition_number_1(J, lu);
    if (!(rep.condition <= opt.max_condition))
      return fail(StepStatus::Singular, "the step matrix (Proposition 2) is singular (condition " +
                                            format_number(rep.condition) + " > " +
                                            format_number(opt.max_condition) + ")");
    const Vec<double, nz> dz = lu.solve(-F);
    Vec<double, nz> scale;
    scale.template head<D::r>() = z.p.cwiseAbs();
    scale.template segment<D::d>(D::r).setZero();
    scale.template tail<D::m>() = z.lam.cwiseAbs();
    apply_correction(z, dz);
    if (((dz.cwiseAbs().array() - opt.step_tolerance * (1.0 + scale.array())) <= 0.0).all()) {
      rep.status = StepStatus::Converged;
      return rep;
    }
  }
  return fail(StepStatus::NotConverged, "Newton did not converge in " + std::to_string(opt.max_iterations) +
                                            " iterations (residual " + format_number(rep.residual) + ")");
}

// dz/d(state) at a solved step (nz x state), by the implicit function theorem.
template <class P>
Eigen::Matrix<double, Dims<P>::unknowns, Dims<P>::state> step_sensitivity(const P& problem, double h,
                                                                          const FlowState<P>& s,
                                                                          const StepUnknowns<P>& z) {
  using D = Dims<P>;
  constexpr int nz = D::unknowns, ns = D::state;
  Vec<double, nz> F;
  Eigen::Matrix<double, nz, nz + ns> J;
  evaluate_step<P, nz + ns>(problem, h, s, z, true, F, J);
  const Eigen::Matrix<double, nz, nz> Jz = J.template leftCols<nz>();
  const Eigen::Matrix<double, nz, ns> Js = J.template rightCols<ns>();
  return -Jz.partialPivLu().solve(Js);
}

}  // namespace lpshoot
