// A Galerkin trajectory carried to another grid of the same horizon, as a guess (a warm start
// from a coarser solve; METHOD.md §9 for the interval's increment form).
//
// Refining (new step h' = ρ h, ρ ≤ 1): each new interval is the old curve restricted to
// [τ0, τ0 + ρ] of the old interval holding its start. The shape curve of an interval is
// p(τ) = x + h τ v + h² (X2 H01 + V1 H11 + Σ_j a_j β_j); with D_k = d^k/dτ^k (X2 H01 + V1 H11 +
// Σ a_j β_j) at τ0, the restricted curve's τ'^k coefficient is ρ^k h² D_k / k!, so
//   X2' = Σ_k ρ^(k-2) D_k / k!,   V1' = Σ_k ρ^(k-2) D_k / (k-1)!,
// and its bubbles a' solve Σ_j a'_j [β_j]_k = ρ^(k-2) D_k / k! (k = 4..S; β_j has degree 4 + j):
// no difference of nearly equal nodes is formed, so the increments keep their relative accuracy
// at any ratio. The group curve ξ(τ) = h τ ω0 + h² (Z2 H01 + Z1 H11 + Σ b_j β_j) (ζ = h ω0 +
// h² Z2, ω1 = ω0 + h Z1) gives W' = exp(ξ(τ0))⁻¹ exp(ξ(τ0 + ρ)), Ω from its body velocity plus
// the connection, and its bubbles the same way (to first order in BCH).
// Coarsening (ρ > 1): node data are taken at the new nodes and the increments are differences
// of them (h' is large there); bubbles start at zero.
// Multipliers (densities: L~ = h Σ b_i (ℓ + λ·χ)) are interpolated through the old interval's
// Gauss values at each new Gauss point's time.
#pragma once

#include <lpshoot/core/galerkin.hpp>
#include <lpshoot/core/galerkin_flow.hpp>
#include <lpshoot/core/group_jets.hpp>
#include <lpshoot/core/hermite.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lpshoot {
namespace detail {

// (X2', V1', a') of the restriction described above, for one component: a and a' with stride.
template <int S>
void restrict_increments(double X2, double V1, const double* a, int stride, double tau0, double rho, double& X2n,
                         double& V1n, double* an) {
  double D[S + 1] = {}, target[S + 1] = {};
  for (int k = 2; k <= S; ++k) {
    D[k] = X2 * hermite_basis(2, k, tau0) + V1 * hermite_basis(3, k, tau0);
    for (int j = 0; j + 4 <= S; ++j) D[k] += a[j * stride] * hermite_basis(4 + j, k, tau0);
  }
  X2n = V1n = 0;
  double rk = 1, factorial = 1;  // ρ^(k-2), k!
  for (int k = 2; k <= S; ++k) {
    factorial *= k;
    target[k] = rk * D[k] / factorial;
    X2n += target[k];
    V1n += k * target[k];
    rk *= rho;
  }
  for (int j = S - 4; j >= 0; --j) {  // back substitution from the highest degree
    double rest = target[4 + j];
    for (int i = j + 1; i <= S - 4; ++i) rest -= an[i * stride] * hermite_basis_coefficients(4 + i)[4 + j];
    an[j * stride] = rest / hermite_basis_coefficients(4 + j)[4 + j];
  }
}

// The value and τ-slope of h² (X2 H01 + V1 H11 + Σ a_j β_j) + (x + h τ v) at τ (a with stride).
template <int S>
void curve_at(double x, double v, double X2, double V1, const double* a, int stride, double h, double tau, double& p,
              double& dp_dt) {
  double c0 = X2 * hermite_basis(2, 0, tau) + V1 * hermite_basis(3, 0, tau);
  double c1 = X2 * hermite_basis(2, 1, tau) + V1 * hermite_basis(3, 1, tau);
  for (int j = 0; j + 4 <= S; ++j) {
    c0 += a[j * stride] * hermite_basis(4 + j, 0, tau);
    c1 += a[j * stride] * hermite_basis(4 + j, 1, tau);
  }
  p = x + h * tau * v + h * h * c0;
  dp_dt = v + h * c1;
}

// Lagrange interpolation through the Q Gauss points of [0, 1] at τ (any τ: extrapolates).
template <int S, int Q>
double gauss_interpolate(const double* values, int stride, double tau) {
  const auto& c = GalerkinTable<S, Q>::get().c;
  double out = 0;
  for (int i = 0; i < Q; ++i) {
    double l = 1;
    for (int j = 0; j < Q; ++j)
      if (j != i) l *= (tau - c[j]) / (c[i] - c[j]);
    out += l * values[i * stride];
  }
  return out;
}

}  // namespace detail

template <class Sch>
GalerkinTrajectory<Sch> resample_trajectory(const typename Sch::Model& model, const GalerkinTrajectory<Sch>& old, int N) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d, m = Sch::m, S = Sch::degree, Q = Sch::gauss, nb = Sch::bubbles;
  const int No = old.N();
  if (No < 1 || !(old.h > 0)) throw std::invalid_argument("resample: the trajectory to carry has no intervals");
  if (N < 1) throw std::invalid_argument("resample: N = " + std::to_string(N) + " intervals requested");
  const double H = old.h, T = No * H, h = T / N, rho = h / H;
  GalerkinTrajectory<Sch> tr;
  tr.h = h;
  tr.g0 = old.g0;
  tr.intervals.resize(N);
  const auto g_old = old.group();
  // The old interval holding time t and t's τ there (the last one holds T); a time within
  // rounding of an old node is that node (n h / H is not an integer in floating point).
  auto locate = [&](double t, int& i, double& tau) {
    double s = std::clamp(t / H, 0.0, double(No));
    if (std::abs(s - std::round(s)) <= 1e-9 * std::max(1.0, s)) s = std::round(s);
    i = std::min(static_cast<int>(std::floor(s)), No - 1);
    tau = s - i;
  };
  using Tangent = typename G::template Tangent<double>;
  // The group curve's increments in the shape curve's form (see the file comment).
  auto group_increments = [H](const auto& e, int a, double& Z2, double& Z1) {
    Z2 = (e.zeta(a) - H * e.omega0(a)) / (H * H);
    Z1 = (e.omega1(a) - e.omega0(a)) / H;
  };
  // The old group curve of interval i: ξ and dξ/dt at τ, from its ends and bubbles.
  auto group_curve = [&](int i, double tau, Tangent& xi, Tangent& dxi) {
    if constexpr (d > 0) {
      const auto& iv = old.intervals[i];
      const auto e = group_curve_ends(model, iv, H);
      for (int a = 0; a < d; ++a) {
        double Z2, Z1;
        group_increments(e, a, Z2, Z1);
        detail::curve_at<S>(0.0, e.omega0(a), Z2, Z1, iv.w.data() + Sch::group_bubble(0) + a, d, H, tau, xi(a), dxi(a));
      }
    }
  };
  // Node data (x, v, Ω) and the group element at time t from the old curves.
  auto node_at = [&](double t, Vec<double, r>& x, Vec<double, r>& v, Vec<double, d>& Om,
                     typename G::template Element<double>& g) {
    int i;
    double tau;
    locate(t, i, tau);
    const auto& iv = old.intervals[i];
    for (int a = 0; a < r; ++a)
      detail::curve_at<S>(iv.x(a), iv.v(a), iv.X2(a), iv.V1(a), iv.w.data() + Sch::shape_bubble(0) + a, r, H, tau, x(a), v(a));
    g = g_old[i];
    if constexpr (d > 0) {
      Tangent xi, dxi, ddxi = Tangent::Zero();
      group_curve(i, tau, xi, dxi);
      Vec<double, d> dOm;
      body_velocity_jet<G, double>(xi, dxi, ddxi, Om, dOm);
      Om += connection_velocity_of(model, x, v);
      g = G::compose(g, G::template exp<double>(xi));
    }
  };
  for (int n = 0; n < N; ++n) {
    auto& iv = tr.intervals[n];
    iv.w.setZero();
    const double t0 = n * h, t1 = (n + 1) * h;
    typename G::template Element<double> g0n, g1n;
    Vec<double, r> x1, v1;
    Vec<double, d> Om1;
    node_at(t0, iv.x, iv.v, iv.Om, g0n);
    node_at(t1, x1, v1, Om1, g1n);
    int i;
    double tau0;
    locate(t0, i, tau0);
    const auto& ov = old.intervals[i];
    if (rho <= 1) {
      for (int a = 0; a < r; ++a)
        detail::restrict_increments<S>(ov.X2(a), ov.V1(a), ov.w.data() + Sch::shape_bubble(0) + a, r, tau0, rho, iv.X2(a),
                                       iv.V1(a), iv.w.data() + Sch::shape_bubble(0) + a);
    } else {
      iv.X2 = (x1 - iv.x - h * iv.v) / (h * h);
      iv.V1 = (v1 - iv.v) / h;
    }
    if constexpr (d > 0) {
      iv.O1 = (Om1 - iv.Om) / h;
      iv.W = G::compose(G::inverse(g0n), g1n);
      if (rho <= 1 && nb > 0) {
        const auto e = group_curve_ends(model, ov, H);
        for (int a = 0; a < d; ++a) {
          double Z2, Z1, Z2n, Z1n;
          group_increments(e, a, Z2, Z1);
          detail::restrict_increments<S>(Z2, Z1, ov.w.data() + Sch::group_bubble(0) + a, d, tau0, rho, Z2n, Z1n,
                                         iv.w.data() + Sch::group_bubble(0) + a);
        }
      }
    }
    if constexpr (m > 0) {
      const auto& c = GalerkinTable<S, Q>::get().c;
      for (int q = 0; q < Q; ++q) {
        int j;
        double tau;
        locate(t0 + c[q] * h, j, tau);
        for (int k = 0; k < m; ++k)
          iv.w(Sch::multipliers(q) + k) =
              detail::gauss_interpolate<S, Q>(old.intervals[j].w.data() + Sch::multipliers(0) + k, m, tau);
      }
    }
  }
  return tr;
}

}  // namespace lpshoot
