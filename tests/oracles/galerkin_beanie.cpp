#include "oracles/galerkin_beanie.hpp"

#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <type_traits>

namespace lpshoot::oracles {

// Derivation. Write se(2)'s translations as complex numbers: exp(ρ, φ) = (φ, V(φ) ρ) with
// V(φ) = (e^{iφ} − 1)/(iφ) = ∫₀¹ e^{iφs} ds, and log(θ, t) = (t / V(θ), θ). Each Gauss point's
// group curve exp(ξ(t)), ξ = (ρ, φ) (galerkin.hpp), has translation r = V(φ) ρ and body velocity
// (e^{−iφ} r', φ'); the reduced velocity is Ω = (e^{−iφ} r', φ' + c ψ'), so the beanie's
// constraints (χ0 + i χ1 = Ω12' + i w Ω12 with w = Ω3 − c ψ' = φ', χ2 = Ω3') are
//   χ_c = e^{−iφ} r'' = C0 ρ + C1 ρ' + C2 ρ'',   χ2 = φ'' + c ψ'',
//   C0 = U2 φ'² + U1 φ'', C1 = 2 U1 φ', C2 = U0,   U_k = e^{−iφ} V^(k)(φ),
// with U_k' = U_{k+1} − i U_k (so U_k'' = U_{k+2} − 2i U_{k+1} − U_k). The curve's data are
//   φ^(k) = Σ_j c_kj (a, Zφ, ν3, c_ω)_j,  ρ^(k) = Σ_j c_kj (ω0, Zρ, ω1, c_ρ)_j   (Hermite and,
//   quartic, the bubble h² c β: c below)
// from a = Ω2 − c v and ω0 = Ω0 + i Ω1 (the body velocity at node n), Z = log(W exp(h δ)), and
// the end slope ξ'(h) = Jr(Z)^{-1} ν (ν = Ω_{n+1} − (0, 0, c v_{n+1}), ν3 its angle):
//   ω1 = M(Zφ) ν_c − ν3 D(Zφ) Zρ,   M = e^{iφ}/V, D = V'/V   (from ν_c = e^{−iZφ}(V' ν3 Zρ + V ω1)).
// At δ = 0, W = (θ, t) and E = e^{iθ}: Zρ = (t + E V(h δφ) h (δx + i δy)) / V(θ + h δφ).
// L~ = h Σ_i b_i [½ u² + Re(conj(λ_c) χ_c) + λ_2 χ2] then has its gradient and Hessian by the
// chain rule through the real "base" quantities (a, Zφ, ν3, [c_ω], ω0, Zρ, ω1, [c_ρ]): all linear
// in the coordinates but Zρ and ω1, whose second derivatives are written below.
namespace {

using cd = std::complex<double>;
constexpr cd kI(0.0, 1.0);

// The base quantities: NA angles (a, Zφ, ν3, [c_ω]), then NW complex ones (ω0, Zρ, ω1, [c_ρ]) as
// real and imaginary parts; the coordinates they depend on (kGeoCols) and the shape's.
template <int S>
struct Base {
  using L = GalerkinBeanieLayout<S>;
  static constexpr int NA = 3 + L::bubbles, NW = 3 + L::bubbles, N = NA + 2 * NW;
  static constexpr int re(int j) { return NA + 2 * j; }
  static constexpr int G = 11 + 3 * L::bubbles;  // kGeoCols' length
  static constexpr int shape = 4 + L::bubbles;
  using Vector = Eigen::Matrix<double, N, 1>;
  using Jacobian = Eigen::Matrix<double, N, L::n>;
};

// V^(k)(φ) = ∫₀¹ (i s)^k e^{iφs} ds, k = 0..4: by its series near 0, by parts elsewhere.
std::array<cd, 5> exp_integrals(double phi) {
  std::array<cd, 5> V;
  if (std::abs(phi) <= 1.0) {
    // i^k Σ_m i^m a_m / (m + k + 1), a_m = |φ|^m / m!: even m real, odd m imaginary (and odd in φ).
    double re[5] = {}, im[5] = {};
    double a = 1.0;
    for (int m = 0; m < 40 && a > 1e-20; ++m) {
      const double signed_a = (m & 2) ? -a : a;  // i^m = 1, i, −1, −i
      double* sum = (m & 1) ? im : re;
      for (int k = 0; k < 5; ++k) sum[k] += signed_a / double(m + k + 1);
      a *= std::abs(phi) / double(m + 1);
    }
    cd ik = 1.0;
    for (int k = 0; k < 5; ++k, ik *= kI) V[k] = ik * cd(re[k], phi < 0 ? -im[k] : im[k]);
  } else {  // V^(k) = (i^k e^{iφ} − k i V^(k−1)) / (iφ), V = (e^{iφ} − 1) / (iφ)
    const cd e = std::polar(1.0, phi), ip = kI * phi;
    V[0] = (e - 1.0) / ip;
    cd ik = kI;
    for (int k = 1; k < 5; ++k, ik *= kI) V[k] = (ik * e - double(k) * kI * V[k - 1]) / ip;
  }
  return V;
}

// K = 1/V, M = e^{iφ} K, D = V' K and their first two derivatives, at the angle of Z.
struct EndFunctions {
  cd E, K, K1, K2, M, M1, M2, D, D1, D2;
};

EndFunctions end_functions(double phi) {
  const auto V = exp_integrals(phi);
  EndFunctions f;
  f.E = std::polar(1.0, phi);
  f.K = 1.0 / V[0];
  f.K1 = -V[1] * f.K * f.K;
  f.K2 = 2.0 * V[1] * V[1] * f.K * f.K * f.K - V[2] * f.K * f.K;
  f.M = f.E * f.K;
  f.M1 = f.E * (kI * f.K + f.K1);
  f.M2 = f.E * (-f.K + 2.0 * kI * f.K1 + f.K2);
  f.D = V[1] * f.K;
  f.D1 = V[2] * f.K + V[1] * f.K1;
  f.D2 = V[3] * f.K + 2.0 * V[2] * f.K1 + V[1] * f.K2;
  return f;
}

// Gauss point i of Q: its weight, the time-derivative coefficients c[k][j] of the curve
// h ω0 H10 + Z H01 + h ω1 H11 + h² c β (k-th derivative, j = ω0, Z, ω1, bubble), and the shape's
// p and p'' on (x, v, X2, V1, [a]).
struct GaussPoint {
  double weight;
  double c[3][4];
  double p[5], ddp[5];
};

GaussPoint gauss_point(int Q, int i, double h) {
  const double q5 = 0.5 * std::sqrt(0.6);
  const double t = Q == 2 ? 0.5 + (i == 0 ? -0.5 : 0.5) / std::sqrt(3.0) : 0.5 + (i - 1) * q5;
  GaussPoint g;
  g.weight = Q == 2 ? 0.5 : (i == 1 ? 8.0 / 18.0 : 5.0 / 18.0);
  const double H10[3] = {t - 2 * t * t + t * t * t, 1 - 4 * t + 3 * t * t, -4 + 6 * t};
  const double H01[3] = {3 * t * t - 2 * t * t * t, 6 * t - 6 * t * t, 6 - 12 * t};
  const double H11[3] = {t * t * t - t * t, 3 * t * t - 2 * t, 6 * t - 2};
  const double B[3] = {t * t * (1 - t) * (1 - t), 2 * t - 6 * t * t + 4 * t * t * t, 2 - 12 * t + 12 * t * t};
  double hk = 1.0;  // h^{-k}
  for (int k = 0; k < 3; ++k, hk /= h) {
    g.c[k][0] = h * hk * H10[k];
    g.c[k][1] = hk * H01[k];
    g.c[k][2] = h * hk * H11[k];
    g.c[k][3] = h * h * hk * B[k];
  }
  const double p[5] = {1, h * t, h * h * H01[0], h * h * H11[0], h * h * B[0]};
  const double ddp[5] = {0, 0, H01[2], H11[2], B[2]};
  for (int a = 0; a < 5; ++a) g.p[a] = p[a], g.ddp[a] = ddp[a];
  return g;
}

// The coordinates the shape depends on (x, v, X2, V1, [shape bubble]: the first Base<S>::shape)
// and the group part (the first Base<S>::G).
constexpr int kShapeCols[5] = {0, 1, 5, 6, 13};
constexpr int kGeoCols[14] = {1, 2, 3, 4, 6, 7, 8, 9, 10, 11, 12, 14, 15, 16};

// One Gauss point's χ_c with its derivatives in (s, r) = (φ, φ', φ''; ρ, ρ', ρ''):
// dC[k][m] = ∂C_k/∂s_m, ddC[k][m][l] = ∂²C_k/∂s_m∂s_l.
struct PointConstraint {
  cd C[3], dC[3][3], ddC[3][3][3];
};

PointConstraint point_constraint(const double s[3]) {
  const auto V = exp_integrals(s[0]);
  const cd em = std::polar(1.0, -s[0]);
  cd U[5], dU[3], ddU[3];
  for (int k = 0; k < 5; ++k) U[k] = em * V[k];
  for (int k = 0; k < 3; ++k) {
    dU[k] = U[k + 1] - kI * U[k];
    ddU[k] = U[k + 2] - 2.0 * kI * U[k + 1] - U[k];
  }
  PointConstraint q{};
  const double s1 = s[1], s2 = s[2];
  q.C[0] = U[2] * s1 * s1 + U[1] * s2;
  q.C[1] = 2.0 * U[1] * s1;
  q.C[2] = U[0];
  q.dC[0][0] = dU[2] * s1 * s1 + dU[1] * s2, q.dC[0][1] = 2.0 * U[2] * s1, q.dC[0][2] = U[1];
  q.dC[1][0] = 2.0 * dU[1] * s1, q.dC[1][1] = 2.0 * U[1];
  q.dC[2][0] = dU[0];
  q.ddC[0][0][0] = ddU[2] * s1 * s1 + ddU[1] * s2;
  q.ddC[0][0][1] = q.ddC[0][1][0] = 2.0 * dU[2] * s1;
  q.ddC[0][0][2] = q.ddC[0][2][0] = dU[1];
  q.ddC[0][1][1] = 2.0 * U[2];
  q.ddC[1][0][0] = 2.0 * ddU[1] * s1;
  q.ddC[1][0][1] = q.ddC[1][1][0] = 2.0 * dU[1];
  q.ddC[2][0][0] = ddU[0];
  return q;
}

// The interval's base quantities and what their nonlinear parts need.
template <int S>
struct BaseValues {
  using B = Base<S>;
  double ang[B::NA];  // a, Zφ, ν3, [c_ω]
  cd w[B::NW];        // ω0, Zρ, ω1, [c_ρ]
  cd nu, Wt;          // ν_c, W's translation
  EndFunctions f;     // at Zφ = W's angle
  cd g_Zrho;          // ∂ω1/∂Zρ (complex-linear)
  typename B::Jacobian J;
};

template <int S>
BaseValues<S> base_values(const problems::BeanieParameters& par, double h, const GalerkinBeanieInterval<S>& iv) {
  using B = Base<S>;
  const double c = par.c();
  const auto& y = iv.y;
  BaseValues<S> b;
  b.ang[0] = y(4) - c * y(1);
  b.ang[1] = iv.W_angle;
  b.ang[2] = y(4) + h * y(9) - c * (y(1) + h * y(6));
  b.nu = cd(y(2) + h * y(7), y(3) + h * y(8));
  b.Wt = cd(iv.W_t(0), iv.W_t(1));
  b.f = end_functions(iv.W_angle);
  const EndFunctions& f = b.f;
  b.w[0] = cd(y(2), y(3));
  b.w[1] = b.Wt * f.K;
  b.w[2] = f.M * b.nu - b.ang[2] * f.D * b.w[1];
  b.g_Zrho = -b.ang[2] * f.D;
  if constexpr (S == 4) b.ang[3] = iv.aux(3), b.w[3] = cd(iv.aux(1), iv.aux(2));  // group bubble (v_x, v_y, ω)

  auto& J = b.J;
  J.setZero();
  J(0, 4) = 1, J(0, 1) = -c;
  J(1, 12) = h;
  J(2, 4) = 1, J(2, 9) = h, J(2, 1) = -c, J(2, 6) = -c * h;
  J(B::re(0), 2) = 1, J(B::re(0) + 1, 3) = 1;
  const cd dZ[3] = {f.E * h * f.K, kI * f.E * h * f.K, b.Wt * f.K1 * h};  // ∂Zρ/∂δ
  for (int a = 0; a < 3; ++a) J(B::re(1), 10 + a) = dZ[a].real(), J(B::re(1) + 1, 10 + a) = dZ[a].imag();
  // ∇ω1 = (M' ν − ν3 D' Zρ) ∇Zφ + M ∇ν − D Zρ ∇ν3 + g_Zρ ∇Zρ
  Eigen::Matrix<cd, 1, GalerkinBeanieLayout<S>::n> w1 = (-f.D * b.w[1]) * J.row(2).template cast<cd>();
  w1(12) += (f.M1 * b.nu - b.ang[2] * f.D1 * b.w[1]) * h;
  w1(2) += f.M, w1(7) += h * f.M;
  w1(3) += kI * f.M, w1(8) += kI * h * f.M;
  for (int a = 0; a < 3; ++a) w1(10 + a) += b.g_Zrho * dZ[a];
  J.row(B::re(2)) = w1.real(), J.row(B::re(2) + 1) = w1.imag();
  if constexpr (S == 4) J(3, 16) = 1, J(B::re(3), 14) = 1, J(B::re(3) + 1, 15) = 1;
  return b;
}

template <int S, bool WithHessian>
void interval_derivatives(const problems::BeanieParameters& par, double h, const GalerkinBeanieInterval<S>& iv,
                          GalerkinBeanieVector<S>& g, GalerkinBeanieMatrix<S>* H) {
  using L = GalerkinBeanieLayout<S>;
  using B = Base<S>;
  constexpr int NA = B::NA, NW = B::NW, Q = L::gauss, G = B::G, NS = B::shape, lam0 = L::multipliers;
  const double mu = par.mu(), c = par.c(), A = par.amplitude;
  const BaseValues<S> b = base_values<S>(par, h, iv);
  auto coordinate = [&](int k) { return k < 10 ? iv.y(k) : iv.aux(k - 13); };  // x, v, X2, V1 or aux
  typename B::Vector Gb = B::Vector::Zero();  // Σ w_i Re(conj(λ_i) ∂χ_i/∂base)
  Eigen::Matrix<double, B::N, B::N> Hb = Eigen::Matrix<double, B::N, B::N>::Zero();
  Eigen::Matrix<double, B::N, 2 * Q> Lb;       // ∂²L~/∂base∂(λ0, λ1) per point
  g.setZero();
  if constexpr (WithHessian) H->setZero();
  for (int i = 0; i < Q; ++i) {
    const GaussPoint P = gauss_point(Q, i, h);
    const double wi = h * P.weight;
    double s[3];
    cd r[3];
    for (int k = 0; k < 3; ++k) {
      s[k] = 0, r[k] = 0;
      for (int j = 0; j < NA; ++j) s[k] += P.c[k][j] * b.ang[j];
      for (int j = 0; j < NW; ++j) r[k] += P.c[k][j] * b.w[j];
    }
    const PointConstraint q = point_constraint(s);
    const cd chi = q.C[0] * r[0] + q.C[1] * r[1] + q.C[2] * r[2];
    cd chi_s[3];  // ∂χ/∂s_m
    for (int m = 0; m < 3; ++m) chi_s[m] = q.dC[0][m] * r[0] + q.dC[1][m] * r[1] + q.dC[2][m] * r[2];
    Eigen::Matrix<cd, B::N, 1> gchi;  // ∂χ/∂base
    for (int j = 0; j < NA; ++j) gchi(j) = P.c[0][j] * chi_s[0] + P.c[1][j] * chi_s[1] + P.c[2][j] * chi_s[2];
    for (int j = 0; j < NW; ++j) {
      const cd Ew = P.c[0][j] * q.C[0] + P.c[1][j] * q.C[1] + P.c[2][j] * q.C[2];
      gchi(B::re(j)) = Ew, gchi(B::re(j) + 1) = kI * Ew;
    }
    const int li = lam0 + 3 * i;  // point i's multipliers' coordinates
    const cd lam(coordinate(li), coordinate(li + 1));
    const double lam2 = coordinate(li + 2);
    Gb += wi * (std::conj(lam) * gchi).real();
    Lb.col(2 * i) = wi * gchi.real(), Lb.col(2 * i + 1) = wi * gchi.imag();
    g(li) = wi * chi.real(), g(li + 1) = wi * chi.imag();

    // χ2 = φ'' + c ψ'' (linear) and ℓ = ½ u², u = μ ψ'' + a sin ψ.
    double pv = 0, ddpv = 0;
    for (int a = 0; a < NS; ++a) {
      const double ya = coordinate(kShapeCols[a]);
      pv += P.p[a] * ya, ddpv += P.ddp[a] * ya;
    }
    g(li + 2) = wi * (s[2] + c * ddpv);
    GalerkinBeanieVector<S> chi2 = GalerkinBeanieVector<S>::Zero();
    for (int j = 0; j < NA; ++j) chi2 += P.c[2][j] * b.J.row(j).transpose();
    for (int a = 0; a < NS; ++a) chi2(kShapeCols[a]) += c * P.ddp[a];
    g += (wi * lam2) * chi2;
    const double u = mu * ddpv + A * std::sin(pv), up = A * std::cos(pv), upp = -A * std::sin(pv);
    double du[5];
    for (int a = 0; a < NS; ++a) du[a] = mu * P.ddp[a] + up * P.p[a];
    for (int a = 0; a < NS; ++a) g(kShapeCols[a]) += wi * u * du[a];

    if constexpr (WithHessian) {
      H->col(li + 2) += wi * chi2;
      H->row(li + 2) += wi * chi2.transpose();
      for (int a = 0; a < NS; ++a)
        for (int e = 0; e < NS; ++e)
          (*H)(kShapeCols[a], kShapeCols[e]) += wi * (du[a] * du[e] + u * upp * P.p[a] * P.p[e]);
      // Re(conj(λ) ∂²χ/∂base²): angle–angle through ∂²χ/∂s², angle–(ω0, Zρ, ω1, [c_ρ]) through
      // ∂C/∂s (∂²χ/∂ang_j ∂w_l = Σ_m c_mj Σ_k c_kl ∂C_k/∂s_m; ∂/∂Im w_l is i ∂/∂Re w_l); none else.
      // conj(λ) first, then real products.
      const cd wl = wi * std::conj(lam);
      Eigen::Matrix3d Css;
      Eigen::Matrix<double, 3, NA> Cm;
      Eigen::Matrix<double, 3, NW> Tre, Tim;
      for (int m = 0; m < 3; ++m) {
        for (int l = 0; l < 3; ++l)
          Css(m, l) = (wl * (q.ddC[0][m][l] * r[0] + q.ddC[1][m][l] * r[1] + q.ddC[2][m][l] * r[2])).real();
        for (int l = 0; l < NA; ++l) Cm(m, l) = P.c[m][l];
        for (int l = 0; l < NW; ++l) {
          const cd T = wl * (q.dC[0][m] * P.c[0][l] + q.dC[1][m] * P.c[1][l] + q.dC[2][m] * P.c[2][l]);
          Tre(m, l) = T.real(), Tim(m, l) = -T.imag();
        }
      }
      Hb.template topLeftCorner<NA, NA>() += Cm.transpose() * Css * Cm;
      const Eigen::Matrix<double, NA, NW> Xre = Cm.transpose() * Tre, Xim = Cm.transpose() * Tim;
      for (int l = 0; l < NW; ++l) {
        Hb.template block<NA, 1>(0, B::re(l)) += Xre.col(l), Hb.template block<NA, 1>(0, B::re(l) + 1) += Xim.col(l);
        Hb.template block<1, NA>(B::re(l), 0) += Xre.col(l).transpose();
        Hb.template block<1, NA>(B::re(l) + 1, 0) += Xim.col(l).transpose();
      }
    }
  }
  g += b.J.transpose() * Gb;
  if constexpr (WithHessian) {
    GalerkinBeanieMatrix<S>& Hm = *H;
    // The base quantities depend on G of the coordinates: the products run on those columns.
    Eigen::Matrix<double, B::N, G> Jc;
    for (int a = 0; a < G; ++a) Jc.col(a) = b.J.col(kGeoCols[a]);
    Eigen::Matrix<double, G, G> Hc = Jc.transpose().lazyProduct(Hb.lazyProduct(Jc));
    const Eigen::Matrix<double, G, 2 * Q> Lc = Jc.transpose().lazyProduct(Lb);
    for (int i = 0; i < Q; ++i)
      for (int k = 0; k < 2; ++k)
        for (int a = 0; a < G; ++a) {
          Hm(kGeoCols[a], lam0 + 3 * i + k) += Lc(a, 2 * i + k);
          Hm(lam0 + 3 * i + k, kGeoCols[a]) += Lc(a, 2 * i + k);
        }
    // The nonlinear base quantities' second derivatives, weighted by Gb: ω1's through its level-0
    // inputs (Zφ, Re ν, Im ν, ν3, Re Zρ, Im Zρ) and Zρ's in δ. G5 ∇²Re Zρ + G6 ∇²Im Zρ =
    // Re((G5 − i G6) ∇²Zρ), likewise for ω1.
    const EndFunctions& f = b.f;
    const cd kappa(Gb(B::re(2)), -Gb(B::re(2) + 1)), kappaZ(Gb(B::re(1)), -Gb(B::re(1) + 1));
    const double nu3 = b.ang[2];
    const cd Zrho = b.w[1];
    Eigen::Matrix<double, 6, G> J0 = Eigen::Matrix<double, 6, G>::Zero();  // columns kGeoCols
    J0(0, 10) = h;               // Zφ: δφ
    J0(1, 1) = 1, J0(1, 5) = h;  // Re ν: Ω0, O1_0
    J0(2, 2) = 1, J0(2, 6) = h;  // Im ν: Ω1, O1_1
    J0.row(3) = Jc.row(2);
    J0.row(4) = Jc.row(B::re(1)), J0.row(5) = Jc.row(B::re(1) + 1);
    Eigen::Matrix<cd, 6, 6> H0 = Eigen::Matrix<cd, 6, 6>::Zero();
    H0(0, 0) = f.M2 * b.nu - nu3 * f.D2 * Zrho;
    H0(0, 1) = f.M1, H0(0, 2) = kI * f.M1, H0(0, 3) = -f.D1 * Zrho;
    H0(0, 4) = -nu3 * f.D1, H0(0, 5) = -kI * nu3 * f.D1;
    H0(3, 4) = -f.D, H0(3, 5) = -kI * f.D;
    for (int a = 0; a < 6; ++a)
      for (int e = 0; e < a; ++e) H0(a, e) = H0(e, a);
    const Eigen::Matrix<double, 6, 6> W0 = (kappa * H0).real();
    Hc += J0.transpose().lazyProduct(W0.lazyProduct(J0));
    for (int a = 0; a < G; ++a)
      for (int e = 0; e < G; ++e) Hm(kGeoCols[a], kGeoCols[e]) += Hc(a, e);
    const cd wZ = kappaZ + kappa * b.g_Zrho;
    const cd hZ22 = b.Wt * f.K2 * h * h, hZ20 = f.E * h * h * (f.K1 + 0.5 * kI * f.K), hZ21 = kI * hZ20;
    Hm(12, 12) += (wZ * hZ22).real();
    Hm(12, 10) += (wZ * hZ20).real(), Hm(10, 12) += (wZ * hZ20).real();
    Hm(12, 11) += (wZ * hZ21).real(), Hm(11, 12) += (wZ * hZ21).real();
  }
}

// Newton's test (the engine's default) and the allowance of a predicted end (newton.hpp's
// predicted_step_allowance): every correction |dz_i| <= tolerance (1 + |z_i|).
constexpr double tolerance = 1e-12, allowance = 16.0;

// SE(2) in complex form: (θ, t) (θ', t') = (θ + θ', t + e^{iθ} t'), log (θ, t) = (t / V(θ), θ).
struct Planar {
  double angle;
  cd t;
};
Planar compose(const Planar& a, const Planar& b) { return {a.angle + b.angle, a.t + std::polar(1.0, a.angle) * b.t}; }
Planar inverse(const Planar& a) { return {-a.angle, -(std::polar(1.0, -a.angle) * a.t)}; }
Eigen::Vector3d log_of(const Planar& a) {
  const cd rho = a.t / exp_integrals(a.angle)[0];
  return Eigen::Vector3d(rho.real(), rho.imag(), a.angle);
}
template <int S>
Planar increment_of(const GalerkinBeanieInterval<S>& iv) { return {iv.W_angle, cd(iv.W_t(0), iv.W_t(1))}; }

// W exp(h ζ) in complex form.
void move_increment(double& angle, Eigen::Vector2d& t, const Eigen::Vector3d& zeta, double h) {
  const cd moved = cd(t(0), t(1)) + std::polar(1.0, angle) * exp_integrals(h * zeta(2))[0] * (h * cd(zeta(0), zeta(1)));
  t = Eigen::Vector2d(moved.real(), moved.imag());
  angle += h * zeta(2);
}

// Ad_{W^{-1}} on (v_x, v_y, ω): Ad_(θ,t) = [[R(θ), (t_y, −t_x)ᵀ], [0, 0, 1]].
Eigen::Matrix3d Ad_inverse(double angle, const Eigen::Vector2d& t) {
  const double cs = std::cos(angle), sn = std::sin(angle);
  const Eigen::Vector2d ti(-(cs * t(0) + sn * t(1)), -(-sn * t(0) + cs * t(1)));  // −R(θ)ᵀ t
  Eigen::Matrix3d m;
  m << cs, sn, ti(1), -sn, cs, -ti(0), 0, 0, 1;
  return m;
}

// Br(i, j) = f · [e_i, e_j] on se(2): [e1, e3] = −e2, [e2, e3] = e1.
Eigen::Matrix3d bracket(const Eigen::Vector3d& f) {
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  B(0, 2) = -f(1), B(2, 0) = f(1);
  B(1, 2) = f(0), B(2, 1) = -f(0);
  return B;
}

// Node n's equations: ∂/∂(x_n, v_n, Ω_n) and ∂/∂η (g_n → g_n exp(h η)) of L~_{n-1} + L~_n with
// the other nodes fixed, then interval n's own (bubbles, constraints). Interval n-1 (left) moves by
// X2 += δx/h², V1 += δv/h, O1 += δΩ/h, δ += η; interval n (right) by x, v, Ω themselves,
// X2 −= (δx + h δv)/h², V1 −= δv/h, O1 −= δΩ/h and δ −= Ad_{W_n^{-1}} η
// (exp(−hη) W = W exp(−h Ad_{W^{-1}} η)).
template <int S, int C>
Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, C> right_rows(
    const Eigen::Matrix<double, GalerkinBeanieLayout<S>::n, C>& M, const Eigen::Matrix3d& Ad, double h) {
  constexpr int aux = GalerkinBeanieLayout<S>::aux;
  Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, C> R;
  R.row(0) = M.row(0) - M.row(5) / (h * h);
  R.row(1) = M.row(1) - (M.row(5) + M.row(6)) / h;
  R.template middleRows<3>(2) = M.template middleRows<3>(2) - M.template middleRows<3>(7) / h;
  R.template middleRows<3>(5) = -Ad.transpose() * M.template middleRows<3>(10);
  R.template bottomRows<aux>() = M.template bottomRows<aux>();
  return R;
}

template <int S, int C>
Eigen::Matrix<double, 8, C> left_rows(const Eigen::Matrix<double, GalerkinBeanieLayout<S>::n, C>& M, double h) {
  Eigen::Matrix<double, 8, C> L;
  L.row(0) = M.row(5) / (h * h);
  L.row(1) = M.row(6) / h;
  L.template middleRows<3>(2) = M.template middleRows<3>(7) / h;
  L.template bottomRows<3>() = M.template middleRows<3>(10);
  return L;
}

// ∂E/∂z: interval n's Hessian in its unknowns (columns 5 on), and in the η rows the ζ columns'
// terms from re-centring at W exp(h ζ): (h/2) Σ_j Ad(j, r) Br(i, j) (Baker–Campbell–Hausdorff,
// the gradient's move and Ad_{W^{-1}}'s together).
template <int S>
Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, GalerkinBeanieLayout<S>::unknowns> unknowns_matrix(
    const Eigen::Matrix<double, GalerkinBeanieLayout<S>::unknowns, GalerkinBeanieLayout<S>::n>& RH,
    const GalerkinBeanieVector<S>& gr, const Eigen::Matrix3d& Ad, double h) {
  constexpr int nz = GalerkinBeanieLayout<S>::unknowns;
  Eigen::Matrix<double, nz, nz> J = RH.template rightCols<nz>();
  J.template block<3, 3>(5, 5) += (0.5 * h) * (Ad.transpose() * bracket(gr.template segment<3>(10)).transpose());
  return J;
}

template <int S>
GalerkinBeanieInterval<S> step_start(const GalerkinBeanieInterval<S>& s, double h) {
  GalerkinBeanieInterval<S> z = s;
  z.y(0) = s.y(0) + h * s.y(1) + h * h * s.y(5);
  z.y(1) = s.y(1) + h * s.y(6);
  z.y.template segment<3>(2) = s.y.template segment<3>(2) + h * s.y.template segment<3>(7);
  return z;
}

template <int S>
double correction_size(const GalerkinBeanieUnknowns<S>& dz, const GalerkinBeanieInterval<S>& z) {
  constexpr int aux = GalerkinBeanieLayout<S>::aux;
  GalerkinBeanieUnknowns<S> scale = GalerkinBeanieUnknowns<S>::Zero();
  scale.template head<5>() = z.y.template segment<5>(5).cwiseAbs();
  scale.template tail<aux>() = z.aux.cwiseAbs();
  const double size = (dz.cwiseAbs().array() / (1.0 + scale.array())).maxCoeff();
  return std::isfinite(size) ? size : std::numeric_limits<double>::infinity();
}

template <int S>
void apply_correction(GalerkinBeanieInterval<S>& z, const GalerkinBeanieUnknowns<S>& dz, double h) {
  z.y.template segment<5>(5) += dz.template head<5>();
  move_increment(z.W_angle, z.W_t, dz.template segment<3>(5), h);
  z.aux += dz.template tail<GalerkinBeanieLayout<S>::aux>();
}

template <int S>
GalerkinBeanieUnknowns<S> unknowns_relative_to(const GalerkinBeanieInterval<S>& z, const GalerkinBeanieInterval<S>& s,
                                               double h) {
  GalerkinBeanieUnknowns<S> u;
  u << z.y.template segment<5>(5), log_of(compose(inverse(increment_of(s)), increment_of(z))) / h, z.aux;
  return u;
}

// The engine flow's predictor (galerkin_flow.hpp, extrapolate): interval n's unknowns
// extrapolated from intervals n-3 (if given: quadratic; else linear), n-2 and n-1, W_n as
// W_{n-1} D with log D extrapolated from the last increments D_k = W_{k-1}^{-1} W_k.
template <int S>
GalerkinBeanieUnknowns<S> extrapolate(const GalerkinBeanieInterval<S>* a0, const GalerkinBeanieInterval<S>& a,
                                      const GalerkinBeanieInterval<S>& b, double h) {
  const GalerkinBeanieInterval<S>& c = a0 ? *a0 : a;
  auto ext = [&](const auto& xa0, const auto& xa, const auto& xb) {
    using V = Eigen::Matrix<double, std::decay_t<decltype(xb)>::RowsAtCompileTime, 1>;
    return a0 ? V(3 * xb - 3 * xa + xa0) : V(2 * xb - xa);
  };
  GalerkinBeanieUnknowns<S> p;
  p.template head<5>() = ext(c.y.template segment<5>(5), a.y.template segment<5>(5), b.y.template segment<5>(5));
  const Eigen::Vector3d last = log_of(compose(inverse(increment_of(a)), increment_of(b)));
  p.template segment<3>(5) =
      (a0 ? Eigen::Vector3d(2 * last - log_of(compose(inverse(increment_of(*a0)), increment_of(a)))) : last) / h;
  p.template tail<GalerkinBeanieLayout<S>::aux>() = ext(c.aux, a.aux, b.aux);
  return p;
}

}  // namespace

template <int S>
double galerkin_beanie_action(const problems::BeanieParameters& par, double h, const GalerkinBeanieInterval<S>& iv,
                              const Eigen::Vector3d& delta) {
  using L = GalerkinBeanieLayout<S>;
  constexpr int NA = Base<S>::NA, NS = Base<S>::shape;
  const double mu = par.mu(), c = par.c(), A = par.amplitude;
  const auto& y = iv.y;
  auto coordinate = [&](int k) { return k < 10 ? iv.y(k) : iv.aux(k - 13); };
  double Zphi = iv.W_angle;
  Eigen::Vector2d t = iv.W_t;
  move_increment(Zphi, t, delta, h);
  const auto V = exp_integrals(Zphi);
  const cd Zrho = cd(t(0), t(1)) / V[0];
  double ang[4] = {y(4) - c * y(1), Zphi, y(4) + h * y(9) - c * (y(1) + h * y(6)), 0.0};
  const cd nu(y(2) + h * y(7), y(3) + h * y(8));
  cd w[4] = {cd(y(2), y(3)), Zrho, std::polar(1.0, Zphi) * nu / V[0] - ang[2] * V[1] / V[0] * Zrho, 0.0};
  if constexpr (S == 4) ang[3] = iv.aux(3), w[3] = cd(iv.aux(1), iv.aux(2));
  double action = 0;
  for (int i = 0; i < L::gauss; ++i) {
    const GaussPoint P = gauss_point(L::gauss, i, h);
    double s[3] = {0, 0, 0};
    cd r[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < NA; ++j) s[k] += P.c[k][j] * ang[j], r[k] += P.c[k][j] * w[j];
    // χ_c = e^{−iφ} (V'' φ'² ρ + V' φ'' ρ + 2 V' φ' ρ' + V ρ'')
    const auto Vs = exp_integrals(s[0]);
    const cd chi = std::polar(1.0, -s[0]) *
                   (Vs[2] * s[1] * s[1] * r[0] + Vs[1] * s[2] * r[0] + 2.0 * Vs[1] * s[1] * r[1] + Vs[0] * r[2]);
    double pv = 0, ddpv = 0;
    for (int a = 0; a < NS; ++a)
      pv += P.p[a] * coordinate(kShapeCols[a]), ddpv += P.ddp[a] * coordinate(kShapeCols[a]);
    const double u = mu * ddpv + A * std::sin(pv), chi2 = s[2] + c * ddpv;
    const int li = L::multipliers + 3 * i;
    action += h * P.weight *
              (0.5 * u * u + coordinate(li) * chi.real() + coordinate(li + 1) * chi.imag() + coordinate(li + 2) * chi2);
  }
  return action;
}

template <int S>
GalerkinBeanieDerivatives<S> galerkin_beanie_derivatives(const problems::BeanieParameters& par, double h,
                                                         const GalerkinBeanieInterval<S>& iv) {
  GalerkinBeanieDerivatives<S> d;
  interval_derivatives<S, true>(par, h, iv, d.gradient, &d.hessian);
  return d;
}

template <int S>
GalerkinBeanieVector<S> galerkin_beanie_gradient(const problems::BeanieParameters& par, double h,
                                                 const GalerkinBeanieInterval<S>& iv) {
  GalerkinBeanieVector<S> g;
  interval_derivatives<S, false>(par, h, iv, g, nullptr);
  return g;
}

template <int S>
GalerkinBeanieStep<S> galerkin_beanie_step(const problems::BeanieParameters& par, double h,
                                           const GalerkinBeanieInterval<S>& state, GalerkinBeanieSensitivity<S>* sensitivity,
                                           GalerkinBeanieCarry<S>* carry, const GalerkinBeanieUnknowns<S>* predictor,
                                           bool take_prediction) {
  using L = GalerkinBeanieLayout<S>;
  constexpr int n = L::n, nz = L::unknowns, aux = L::aux;
  using Unknowns = GalerkinBeanieUnknowns<S>;
  const bool carried = carry && carry->valid;
  GalerkinBeanieDerivatives<S> computed;
  const GalerkinBeanieDerivatives<S>& left = carried ? carry->state : computed;
  if (!carried && sensitivity)
    computed = galerkin_beanie_derivatives<S>(par, h, state);
  else if (!carried)
    computed.gradient = galerkin_beanie_gradient<S>(par, h, state);
  const Eigen::Matrix<double, 8, 1> fixed = left_rows<S, 1>(left.gradient, h);

  GalerkinBeanieStep<S> out;
  GalerkinBeanieInterval<S>& z = out.next;
  z = step_start(state, h);
  if (predictor) {
    z.y.template segment<5>(5) = predictor->template head<5>();
    move_increment(z.W_angle, z.W_t, predictor->template segment<3>(5), h);
    z.aux = predictor->template tail<aux>();
  }
  auto residual = [&](const GalerkinBeanieVector<S>& gr, const Eigen::Matrix3d& Ad) {
    Unknowns F = right_rows<S, 1>(gr, Ad, h);
    F.template head<8>() += fixed;
    return F;
  };
  bool done = false, predicted = false;
  if (take_prediction && sensitivity) {  // confirmed (or solved on) at the sensitivity's evaluation
    done = predicted = true;
  } else if (carried) {  // chord iterations on the previous step's matrix while they contract
    double previous = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 10 && !done; ++k) {
      const Unknowns dz =
          -carry->step_matrix.solve(residual(galerkin_beanie_gradient<S>(par, h, z), Ad_inverse(z.W_angle, z.W_t)));
      const double size = correction_size<S>(dz, z);
      if (!(size <= 0.5 * previous)) break;
      apply_correction<S>(z, dz, h);
      ++out.iterations;
      done = size <= tolerance;
      // With a sensitivity to come, end when the next correction, (size / previous) times this
      // one, would be within the allowance: the sensitivity's evaluation confirms it below.
      predicted = !done && sensitivity && std::isfinite(previous) && size <= 0.25 * previous &&
                  size * (size / previous) <= allowance * tolerance;
      done = done || predicted;
      previous = size;
    }
  }
  for (;;) {
    double previous = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 20 && !done; ++k) {
      const GalerkinBeanieDerivatives<S> right = galerkin_beanie_derivatives<S>(par, h, z);
      const Eigen::Matrix3d Ad = Ad_inverse(z.W_angle, z.W_t);
      const Eigen::Matrix<double, nz, n> RH = right_rows<S, n>(right.hessian, Ad, h);
      const Unknowns dz =
          -GalerkinBeanieStepMatrix<S>(unknowns_matrix<S>(RH, right.gradient, Ad, h)).solve(residual(right.gradient, Ad));
      const double size = correction_size<S>(dz, z);
      if (!std::isfinite(size)) break;
      apply_correction<S>(z, dz, h);
      ++out.iterations;
      // Converged, or at the equations' rounding noise (small steps h: corrections that stopped
      // shrinking below the noise bound of the engine's confirmation, 1e-8).
      done = size <= tolerance || (size <= 1e-8 && size > 0.5 * previous);
      previous = size;
    }
    out.converged = done;
    if (!done || !sensitivity) return out;

    // dz/d(state) = −(∂E/∂z)^{-1} ∂E/∂state at the solution.
    GalerkinBeanieDerivatives<S> right = galerkin_beanie_derivatives<S>(par, h, z);
    const Eigen::Matrix3d Ad = Ad_inverse(z.W_angle, z.W_t);
    const Eigen::Matrix<double, nz, n> RH = right_rows<S, n>(right.hessian, Ad, h);
    GalerkinBeanieStepMatrix<S> local;
    GalerkinBeanieStepMatrix<S>& lu = carry ? carry->step_matrix : local;  // the next step's chord matrix
    lu.compute(unknowns_matrix<S>(RH, right.gradient, Ad, h));
    if (predicted) {  // the exact Newton correction here must be within the allowance; it is applied
      const Unknowns dz = -lu.solve(residual(right.gradient, Ad));
      if (!(correction_size<S>(dz, z) <= allowance * tolerance)) {
        done = predicted = false;  // solve on by Newton
        continue;
      }
      apply_correction<S>(z, dz, h);
      // Interval n's carried gradient moved with it to first order (its Hessian; the bracket term
      // re-centres δ at W exp(h ζ)).
      right.gradient += right.hessian.template rightCols<nz>() * dz;
      right.gradient.template segment<3>(10) +=
          (0.5 * h) * (bracket(right.gradient.template segment<3>(10)).transpose() * dz.template segment<3>(5));
    }
    Eigen::Matrix<double, nz, n> Js = Eigen::Matrix<double, nz, n>::Zero();
    Js.template topRows<8>() = left_rows<S, n>(left.hessian, h);
    // The state's δ columns in its η rows: re-centring interval n-1's gradient at W exp(h δ).
    Js.template block<3, 3>(5, 10) += (0.5 * h) * bracket(left.gradient.template segment<3>(10)).transpose();
    // Interval n through its base node: x_n = x + h v + h² X2, v_n = v + h V1, Ω_n = Ω + h O1.
    Js.col(0) += RH.col(0);
    Js.col(1) += h * RH.col(0) + RH.col(1);
    Js.col(5) += (h * h) * RH.col(0);
    Js.col(6) += h * RH.col(1);
    Js.template middleCols<3>(2) += RH.template middleCols<3>(2);
    Js.template middleCols<3>(7) += h * RH.template middleCols<3>(2);
    *sensitivity = -lu.solve(Js);
    if (carry) {
      carry->state = right;
      carry->valid = true;
    }
    return out;
  }
}

template <int S>
GalerkinBeanieFlow<S> galerkin_beanie_flow(const problems::BeanieParameters& par, double h,
                                           const GalerkinBeanieInterval<S>& start, int steps) {
  GalerkinBeanieFlow<S> out;
  out.sensitivity.setIdentity();
  GalerkinBeanieMatrix<S> next;
  GalerkinBeanieSensitivity<S> dz;
  GalerkinBeanieCarry<S> carry;
  GalerkinBeanieInterval<S> s = start, before = start, earlier = start;
  double last_prediction_error = std::numeric_limits<double>::infinity();
  for (int k = 1; k <= steps; ++k) {
    GalerkinBeanieUnknowns<S> p;
    if (k >= 2) p = extrapolate<S>(k >= 3 ? &earlier : nullptr, before, s, h);
    // As the engine: a prediction is taken without iterating when the last one landed within
    // 1/8 of the confirmation's bound (here without the engine's noise term: no condition estimate).
    const bool take = k >= 2 && last_prediction_error <= allowance * tolerance / 8;
    const GalerkinBeanieStep<S> step = galerkin_beanie_step<S>(par, h, s, &dz, &carry, k >= 2 ? &p : nullptr, take);
    out.iterations += step.iterations;
    if (!step.converged) return out;
    if (k >= 2) last_prediction_error = correction_size<S>(unknowns_relative_to<S>(step.next, s, h) - p, step.next);
    constexpr int nz = GalerkinBeanieLayout<S>::unknowns;
    next.row(0) = out.sensitivity.row(0) + h * out.sensitivity.row(1) + (h * h) * out.sensitivity.row(5);
    next.row(1) = out.sensitivity.row(1) + h * out.sensitivity.row(6);
    next.template middleRows<3>(2) = out.sensitivity.template middleRows<3>(2) + h * out.sensitivity.template middleRows<3>(7);
    next.template bottomRows<nz>().noalias() = dz * out.sensitivity;
    out.sensitivity.swap(next);
    earlier = before, before = s, s = step.next;
    ++out.steps;
  }
  out.last = s;
  out.converged = true;
  return out;
}

#define LPSHOOT_GALERKIN_BEANIE(S)                                                                              \
  template double galerkin_beanie_action<S>(const problems::BeanieParameters&, double,                         \
                                            const GalerkinBeanieInterval<S>&, const Eigen::Vector3d&);         \
  template GalerkinBeanieDerivatives<S> galerkin_beanie_derivatives<S>(const problems::BeanieParameters&, double, \
                                                                       const GalerkinBeanieInterval<S>&);      \
  template GalerkinBeanieVector<S> galerkin_beanie_gradient<S>(const problems::BeanieParameters&, double,      \
                                                               const GalerkinBeanieInterval<S>&);              \
  template GalerkinBeanieStep<S> galerkin_beanie_step<S>(                                                      \
      const problems::BeanieParameters&, double, const GalerkinBeanieInterval<S>&, GalerkinBeanieSensitivity<S>*, \
      GalerkinBeanieCarry<S>*, const GalerkinBeanieUnknowns<S>*, bool);                                        \
  template GalerkinBeanieFlow<S> galerkin_beanie_flow<S>(const problems::BeanieParameters&, double,            \
                                                         const GalerkinBeanieInterval<S>&, int);
LPSHOOT_GALERKIN_BEANIE(3)
LPSHOOT_GALERKIN_BEANIE(4)
#undef LPSHOOT_GALERKIN_BEANIE

}  // namespace lpshoot::oracles
