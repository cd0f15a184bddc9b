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
//   φ^(k) = Σ_j c_kj (a, Zφ, ν3)_j,  ρ^(k) = Σ_j c_kj (ω0, Zρ, ω1)_j   (cubic Hermite, c below)
// from a = Ω2 − c v and ω0 = Ω0 + i Ω1 (the body velocity at node n), Z = log(W exp(h δ)), and
// the end slope ξ'(h) = Jr(Z)^{-1} ν (ν = Ω_{n+1} − (0, 0, c v_{n+1}), ν3 its angle):
//   ω1 = M(Zφ) ν_c − ν3 D(Zφ) Zρ,   M = e^{iφ}/V, D = V'/V   (from ν_c = e^{−iZφ}(V' ν3 Zρ + V ω1)).
// At δ = 0, W = (θ, t) and E = e^{iθ}: Zρ = (t + E V(h δφ) h (δx + i δy)) / V(θ + h δφ).
// L~ = h Σ_i b_i [½ u² + Re(conj(λ_c) χ_c) + λ_2 χ2] then has its gradient and Hessian by the
// chain rule through the nine real "base" quantities (a, Zφ, ν3, ω0, Zρ, ω1): the first three
// linear in the coordinates, Zρ and ω1 nonlinear with the second derivatives written below.
namespace {

using cd = std::complex<double>;
constexpr cd kI(0.0, 1.0);
using V19 = GalerkinBeanieVector;
using M19 = GalerkinBeanieMatrix;
using Base = Eigen::Matrix<double, 9, 1>;          // (a, Zφ, ν3, Re ω0, Im ω0, Re Zρ, Im Zρ, Re ω1, Im ω1)
using BaseJacobian = Eigen::Matrix<double, 9, 19>;  // ∂base/∂(y, δ, λ)

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

// Gauss point i: the time-derivative coefficients c[k][j] of the Hermite curve h ω0 H10 + Z H01
// + h ω1 H11 (k-th derivative, j = ω0, Z, ω1), and the shape's p and p'' on (x, v, X2, V1).
struct GaussPoint {
  double c[3][3];
  double p[4], ddp[4];
};

GaussPoint gauss_point(int i, double h) {
  const double t = 0.5 + (i == 0 ? -0.5 : 0.5) / std::sqrt(3.0);
  const double H10[3] = {t - 2 * t * t + t * t * t, 1 - 4 * t + 3 * t * t, -4 + 6 * t};
  const double H01[3] = {3 * t * t - 2 * t * t * t, 6 * t - 6 * t * t, 6 - 12 * t};
  const double H11[3] = {t * t * t - t * t, 3 * t * t - 2 * t, 6 * t - 2};
  GaussPoint g;
  double hk = 1.0;  // h^{-k}
  for (int k = 0; k < 3; ++k, hk /= h) {
    g.c[k][0] = h * hk * H10[k];
    g.c[k][1] = hk * H01[k];
    g.c[k][2] = h * hk * H11[k];
  }
  const double p[4] = {1, h * t, h * h * H01[0], h * h * H11[0]};
  const double ddp[4] = {0, 0, H01[2], H11[2]};
  for (int a = 0; a < 4; ++a) g.p[a] = p[a], g.ddp[a] = ddp[a];
  return g;
}

constexpr int kShapeCols[4] = {0, 1, 5, 6};  // x, v, X2, V1 in the interval's coordinates
constexpr int kGeo = 11;                     // the coordinates the group part depends on
constexpr int kGeoCols[kGeo] = {1, 2, 3, 4, 6, 7, 8, 9, 10, 11, 12};
constexpr double kWeight = 0.5;              // Gauss weights on [0, 1]

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
struct BaseValues {
  double ang[3];    // a, Zφ, ν3
  cd w[3];          // ω0, Zρ, ω1
  cd nu, Wt;        // ν_c, W's translation
  EndFunctions f;   // at Zφ = W's angle
  cd g_Zrho;        // ∂ω1/∂Zρ (complex-linear)
  BaseJacobian J;   // rows: the nine base quantities
};

BaseValues base_values(const problems::BeanieParameters& par, double h, const GalerkinBeanieInterval& iv) {
  const double c = par.c();
  const auto& y = iv.y;
  BaseValues b;
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

  BaseJacobian& J = b.J;
  J.setZero();
  J(0, 4) = 1, J(0, 1) = -c;
  J(1, 12) = h;
  J(2, 4) = 1, J(2, 9) = h, J(2, 1) = -c, J(2, 6) = -c * h;
  J(3, 2) = 1, J(4, 3) = 1;
  const cd dZ[3] = {f.E * h * f.K, kI * f.E * h * f.K, b.Wt * f.K1 * h};  // ∂Zρ/∂δ
  for (int a = 0; a < 3; ++a) J(5, 10 + a) = dZ[a].real(), J(6, 10 + a) = dZ[a].imag();
  // ∇ω1 = (M' ν − ν3 D' Zρ) ∇Zφ + M ∇ν − D Zρ ∇ν3 + g_Zρ ∇Zρ
  Eigen::Matrix<cd, 1, 19> w1 = (-f.D * b.w[1]) * J.row(2).cast<cd>();
  w1(12) += (f.M1 * b.nu - b.ang[2] * f.D1 * b.w[1]) * h;
  w1(2) += f.M, w1(7) += h * f.M;
  w1(3) += kI * f.M, w1(8) += kI * h * f.M;
  for (int a = 0; a < 3; ++a) w1(10 + a) += b.g_Zrho * dZ[a];
  J.row(7) = w1.real(), J.row(8) = w1.imag();
  return b;
}

template <bool WithHessian>
void interval_derivatives(const problems::BeanieParameters& par, double h, const GalerkinBeanieInterval& iv, V19& g,
                          M19* H) {
  const double mu = par.mu(), c = par.c(), A = par.amplitude;
  const BaseValues b = base_values(par, h, iv);
  const auto& y = iv.y;
  Base Gb = Base::Zero();                                     // Σ w_i ∂F_i/∂base
  Eigen::Matrix<double, 9, 9> Hb = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix<double, 9, 4> Lb;                              // ∂²L~/∂base∂(λ0, λ1) per point
  g.setZero();
  if constexpr (WithHessian) H->setZero();
  for (int i = 0; i < 2; ++i) {
    const double wi = h * kWeight;
    const GaussPoint P = gauss_point(i, h);
    double s[3];
    cd r[3];
    for (int k = 0; k < 3; ++k) {
      s[k] = P.c[k][0] * b.ang[0] + P.c[k][1] * b.ang[1] + P.c[k][2] * b.ang[2];
      r[k] = P.c[k][0] * b.w[0] + P.c[k][1] * b.w[1] + P.c[k][2] * b.w[2];
    }
    const PointConstraint q = point_constraint(s);
    const cd chi = q.C[0] * r[0] + q.C[1] * r[1] + q.C[2] * r[2];
    cd chi_s[3];  // ∂χ/∂s_m
    for (int m = 0; m < 3; ++m) chi_s[m] = q.dC[0][m] * r[0] + q.dC[1][m] * r[1] + q.dC[2][m] * r[2];
    Eigen::Matrix<cd, 9, 1> gchi;  // ∂χ/∂base
    for (int j = 0; j < 3; ++j) {
      gchi(j) = P.c[0][j] * chi_s[0] + P.c[1][j] * chi_s[1] + P.c[2][j] * chi_s[2];
      const cd Ew = P.c[0][j] * q.C[0] + P.c[1][j] * q.C[1] + P.c[2][j] * q.C[2];
      gchi(3 + 2 * j) = Ew, gchi(4 + 2 * j) = kI * Ew;
    }
    const cd lam(iv.lambda(3 * i), iv.lambda(3 * i + 1));
    const double lam2 = iv.lambda(3 * i + 2);
    Gb += wi * (std::conj(lam) * gchi).real();
    Lb.col(2 * i) = wi * gchi.real(), Lb.col(2 * i + 1) = wi * gchi.imag();
    g(13 + 3 * i) = wi * chi.real(), g(14 + 3 * i) = wi * chi.imag();

    // χ2 = φ'' + c ψ'' (linear) and ℓ = ½ u², u = μ ψ'' + a sin ψ.
    double pv = 0, ddpv = 0;
    for (int a = 0; a < 4; ++a) pv += P.p[a] * y(kShapeCols[a]), ddpv += P.ddp[a] * y(kShapeCols[a]);
    g(15 + 3 * i) = wi * (s[2] + c * ddpv);
    V19 chi2 = (P.c[2][0] * b.J.row(0) + P.c[2][1] * b.J.row(1) + P.c[2][2] * b.J.row(2)).transpose();
    for (int a = 0; a < 4; ++a) chi2(kShapeCols[a]) += c * P.ddp[a];
    g += (wi * lam2) * chi2;
    const double u = mu * ddpv + A * std::sin(pv), up = A * std::cos(pv), upp = -A * std::sin(pv);
    double du[4];
    for (int a = 0; a < 4; ++a) du[a] = mu * P.ddp[a] + up * P.p[a];
    for (int a = 0; a < 4; ++a) g(kShapeCols[a]) += wi * u * du[a];

    if constexpr (WithHessian) {
      H->col(15 + 3 * i) += wi * chi2;
      H->row(15 + 3 * i) += wi * chi2.transpose();
      for (int a = 0; a < 4; ++a)
        for (int e = 0; e < 4; ++e)
          (*H)(kShapeCols[a], kShapeCols[e]) += wi * (du[a] * du[e] + u * upp * P.p[a] * P.p[e]);
      // Re(conj(λ) ∂²χ/∂base²): angle–angle through ∂²χ/∂s², angle–(ω0, Zρ, ω1) through ∂C/∂s
      // (∂²χ/∂ang_j ∂w_l = Σ_m c_mj Σ_k c_kl ∂C_k/∂s_m; ∂/∂Im w_l is i ∂/∂Re w_l); none else.
      // conj(λ) first, then real 3 x 3 products.
      const cd wl = wi * std::conj(lam);
      Eigen::Matrix3d Css, Tre, Tim, Cm;
      for (int m = 0; m < 3; ++m)
        for (int l = 0; l < 3; ++l) {
          Cm(m, l) = P.c[m][l];
          Css(m, l) = (wl * (q.ddC[0][m][l] * r[0] + q.ddC[1][m][l] * r[1] + q.ddC[2][m][l] * r[2])).real();
          const cd T = wl * (q.dC[0][m] * P.c[0][l] + q.dC[1][m] * P.c[1][l] + q.dC[2][m] * P.c[2][l]);
          Tre(m, l) = T.real(), Tim(m, l) = -T.imag();
        }
      Hb.topLeftCorner<3, 3>() += Cm.transpose() * Css * Cm;
      const Eigen::Matrix3d Xre = Cm.transpose() * Tre, Xim = Cm.transpose() * Tim;
      for (int l = 0; l < 3; ++l) {
        Hb.block<3, 1>(0, 3 + 2 * l) += Xre.col(l), Hb.block<3, 1>(0, 4 + 2 * l) += Xim.col(l);
        Hb.block<1, 3>(3 + 2 * l, 0) += Xre.col(l).transpose(), Hb.block<1, 3>(4 + 2 * l, 0) += Xim.col(l).transpose();
      }
    }
  }
  g += b.J.transpose() * Gb;
  if constexpr (!WithHessian) return;
  else {
    M19& Hm = *H;
    // The base quantities depend on 11 of the 19 coordinates: the products run on those columns.
    Eigen::Matrix<double, 9, kGeo> Jc;
    for (int a = 0; a < kGeo; ++a) Jc.col(a) = b.J.col(kGeoCols[a]);
    Eigen::Matrix<double, kGeo, kGeo> Hc = Jc.transpose().lazyProduct(Hb.lazyProduct(Jc));
    const Eigen::Matrix<double, kGeo, 4> Lc = Jc.transpose().lazyProduct(Lb);
    for (int i = 0; i < 2; ++i)
      for (int k = 0; k < 2; ++k)
        for (int a = 0; a < kGeo; ++a) {
          Hm(kGeoCols[a], 13 + 3 * i + k) += Lc(a, 2 * i + k);
          Hm(13 + 3 * i + k, kGeoCols[a]) += Lc(a, 2 * i + k);
        }
    // The nonlinear base quantities' second derivatives, weighted by Gb: ω1's through its level-0
    // inputs (Zφ, Re ν, Im ν, ν3, Re Zρ, Im Zρ) and Zρ's in δ. G5 ∇²Re Zρ + G6 ∇²Im Zρ =
    // Re((G5 − i G6) ∇²Zρ), likewise for ω1.
    const EndFunctions& f = b.f;
    const cd kappa(Gb(7), -Gb(8)), kappaZ(Gb(5), -Gb(6));
    const double nu3 = b.ang[2];
    const cd Zrho = b.w[1];
    Eigen::Matrix<double, 6, kGeo> J0 = Eigen::Matrix<double, 6, kGeo>::Zero();  // columns kGeoCols
    J0(0, 10) = h;                // Zφ: δφ
    J0(1, 1) = 1, J0(1, 5) = h;   // Re ν: Ω0, O1_0
    J0(2, 2) = 1, J0(2, 6) = h;   // Im ν: Ω1, O1_1
    J0.row(3) = Jc.row(2);
    J0.row(4) = Jc.row(5), J0.row(5) = Jc.row(6);
    Eigen::Matrix<cd, 6, 6> H0 = Eigen::Matrix<cd, 6, 6>::Zero();
    H0(0, 0) = f.M2 * b.nu - nu3 * f.D2 * Zrho;
    H0(0, 1) = f.M1, H0(0, 2) = kI * f.M1, H0(0, 3) = -f.D1 * Zrho;
    H0(0, 4) = -nu3 * f.D1, H0(0, 5) = -kI * nu3 * f.D1;
    H0(3, 4) = -f.D, H0(3, 5) = -kI * f.D;
    for (int a = 0; a < 6; ++a)
      for (int e = 0; e < a; ++e) H0(a, e) = H0(e, a);
    const Eigen::Matrix<double, 6, 6> W0 = (kappa * H0).real();
    Hc += J0.transpose().lazyProduct(W0.lazyProduct(J0));
    for (int a = 0; a < kGeo; ++a)
      for (int e = 0; e < kGeo; ++e) Hm(kGeoCols[a], kGeoCols[e]) += Hc(a, e);
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
Planar increment_of(const GalerkinBeanieInterval& iv) { return {iv.W_angle, cd(iv.W_t(0), iv.W_t(1))}; }

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
// the other nodes fixed, then interval n's constraints. Interval n-1 (left) moves by X2 += δx/h²,
// V1 += δv/h, O1 += δΩ/h, δ += η; interval n (right) by x, v, Ω themselves, X2 −= (δx + h δv)/h²,
// V1 −= δv/h, O1 −= δΩ/h and δ −= Ad_{W_n^{-1}} η (exp(−hη) W = W exp(−h Ad_{W^{-1}} η)).
template <int C>
Eigen::Matrix<double, 14, C> right_rows(const Eigen::Matrix<double, 19, C>& M, const Eigen::Matrix3d& Ad, double h) {
  Eigen::Matrix<double, 14, C> R;
  R.row(0) = M.row(0) - M.row(5) / (h * h);
  R.row(1) = M.row(1) - (M.row(5) + M.row(6)) / h;
  R.template middleRows<3>(2) = M.template middleRows<3>(2) - M.template middleRows<3>(7) / h;
  R.template middleRows<3>(5) = -Ad.transpose() * M.template middleRows<3>(10);
  R.template bottomRows<6>() = M.template bottomRows<6>();
  return R;
}

template <int C>
Eigen::Matrix<double, 8, C> left_rows(const Eigen::Matrix<double, 19, C>& M, double h) {
  Eigen::Matrix<double, 8, C> L;
  L.row(0) = M.row(5) / (h * h);
  L.row(1) = M.row(6) / h;
  L.template middleRows<3>(2) = M.template middleRows<3>(7) / h;
  L.template bottomRows<3>() = M.template middleRows<3>(10);
  return L;
}

// ∂E/∂z: interval n's Hessian in its unknowns (columns 5..18), and in the η rows the ζ columns'
// terms from re-centring at W exp(h ζ): (h/2) Σ_j Ad(j, r) Br(i, j) (Baker–Campbell–Hausdorff,
// the gradient's move and Ad_{W^{-1}}'s together).
Eigen::Matrix<double, 14, 14> unknowns_matrix(const Eigen::Matrix<double, 14, 19>& RH, const V19& gr,
                                              const Eigen::Matrix3d& Ad, double h) {
  Eigen::Matrix<double, 14, 14> J = RH.rightCols<14>();
  J.block<3, 3>(5, 5) += (0.5 * h) * (Ad.transpose() * bracket(gr.segment<3>(10)).transpose());
  return J;
}

GalerkinBeanieInterval step_start(const GalerkinBeanieInterval& s, double h) {
  GalerkinBeanieInterval z = s;
  z.y(0) = s.y(0) + h * s.y(1) + h * h * s.y(5);
  z.y(1) = s.y(1) + h * s.y(6);
  z.y.segment<3>(2) = s.y.segment<3>(2) + h * s.y.segment<3>(7);
  return z;
}

double correction_size(const Eigen::Matrix<double, 14, 1>& dz, const GalerkinBeanieInterval& z) {
  Eigen::Matrix<double, 14, 1> scale = Eigen::Matrix<double, 14, 1>::Zero();
  scale.head<5>() = z.y.segment<5>(5).cwiseAbs();
  scale.tail<6>() = z.lambda.cwiseAbs();
  const double size = (dz.cwiseAbs().array() / (1.0 + scale.array())).maxCoeff();
  return std::isfinite(size) ? size : std::numeric_limits<double>::infinity();
}

void apply_correction(GalerkinBeanieInterval& z, const Eigen::Matrix<double, 14, 1>& dz, double h) {
  z.y.segment<5>(5) += dz.head<5>();
  move_increment(z.W_angle, z.W_t, dz.segment<3>(5), h);
  z.lambda += dz.tail<6>();
}

}  // namespace

double galerkin4_beanie_action(const problems::BeanieParameters& par, double h, const GalerkinBeanieInterval& iv,
                               const Eigen::Vector3d& delta) {
  const double mu = par.mu(), c = par.c(), A = par.amplitude;
  const auto& y = iv.y;
  double Zphi = iv.W_angle;
  Eigen::Vector2d t = iv.W_t;
  move_increment(Zphi, t, delta, h);
  const auto V = exp_integrals(Zphi);
  const cd Zrho = cd(t(0), t(1)) / V[0];
  const double ang[3] = {y(4) - c * y(1), Zphi, y(4) + h * y(9) - c * (y(1) + h * y(6))};
  const cd nu(y(2) + h * y(7), y(3) + h * y(8));
  const cd w[3] = {cd(y(2), y(3)), Zrho, std::polar(1.0, Zphi) * nu / V[0] - ang[2] * V[1] / V[0] * Zrho};
  double L = 0;
  for (int i = 0; i < 2; ++i) {
    const GaussPoint P = gauss_point(i, h);
    double s[3];
    cd r[3];
    for (int k = 0; k < 3; ++k) {
      s[k] = P.c[k][0] * ang[0] + P.c[k][1] * ang[1] + P.c[k][2] * ang[2];
      r[k] = P.c[k][0] * w[0] + P.c[k][1] * w[1] + P.c[k][2] * w[2];
    }
    // χ_c = e^{−iφ} (V'' φ'² ρ + V' φ'' ρ + 2 V' φ' ρ' + V ρ'')
    const auto Vs = exp_integrals(s[0]);
    const cd chi = std::polar(1.0, -s[0]) *
                   (Vs[2] * s[1] * s[1] * r[0] + Vs[1] * s[2] * r[0] + 2.0 * Vs[1] * s[1] * r[1] + Vs[0] * r[2]);
    double pv = 0, ddpv = 0;
    for (int a = 0; a < 4; ++a) pv += P.p[a] * y(kShapeCols[a]), ddpv += P.ddp[a] * y(kShapeCols[a]);
    const double u = mu * ddpv + A * std::sin(pv), chi2 = s[2] + c * ddpv;
    L += h * kWeight *
         (0.5 * u * u + iv.lambda(3 * i) * chi.real() + iv.lambda(3 * i + 1) * chi.imag() + iv.lambda(3 * i + 2) * chi2);
  }
  return L;
}

GalerkinBeanieDerivatives galerkin4_beanie_derivatives(const problems::BeanieParameters& par, double h,
                                                       const GalerkinBeanieInterval& iv) {
  GalerkinBeanieDerivatives d;
  interval_derivatives<true>(par, h, iv, d.gradient, &d.hessian);
  return d;
}

GalerkinBeanieVector galerkin4_beanie_gradient(const problems::BeanieParameters& par, double h,
                                               const GalerkinBeanieInterval& iv) {
  V19 g;
  interval_derivatives<false>(par, h, iv, g, nullptr);
  return g;
}

GalerkinBeanieStep galerkin4_beanie_step(const problems::BeanieParameters& par, double h,
                                         const GalerkinBeanieInterval& state, GalerkinBeanieSensitivity* sensitivity,
                                         GalerkinBeanieCarry* carry, const GalerkinBeanieUnknowns* predictor,
                                         bool take_prediction) {
  const bool carried = carry && carry->valid;
  GalerkinBeanieDerivatives computed;
  const GalerkinBeanieDerivatives& left = carried ? carry->state : computed;
  if (!carried && sensitivity)
    computed = galerkin4_beanie_derivatives(par, h, state);
  else if (!carried)
    computed.gradient = galerkin4_beanie_gradient(par, h, state);
  const Eigen::Matrix<double, 8, 1> fixed = left_rows<1>(left.gradient, h);

  GalerkinBeanieStep out;
  GalerkinBeanieInterval& z = out.next;
  z = step_start(state, h);
  if (predictor) {
    z.y.segment<5>(5) = predictor->head<5>();
    move_increment(z.W_angle, z.W_t, predictor->segment<3>(5), h);
    z.lambda = predictor->tail<6>();
  }
  auto residual = [&](const V19& gr, const Eigen::Matrix3d& Ad) {
    Eigen::Matrix<double, 14, 1> F = right_rows<1>(gr, Ad, h);
    F.head<8>() += fixed;
    return F;
  };
  bool done = false, predicted = false;
  if (take_prediction && sensitivity) {  // confirmed (or solved on) at the sensitivity's evaluation
    done = predicted = true;
  } else if (carried) {  // chord iterations on the previous step's matrix while they contract
    double previous = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 10 && !done; ++k) {
      const Eigen::Matrix<double, 14, 1> dz =
          -carry->step_matrix.solve(residual(galerkin4_beanie_gradient(par, h, z), Ad_inverse(z.W_angle, z.W_t)));
      const double size = correction_size(dz, z);
      if (!(size <= 0.5 * previous)) break;
      apply_correction(z, dz, h);
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
      const GalerkinBeanieDerivatives right = galerkin4_beanie_derivatives(par, h, z);
      const Eigen::Matrix3d Ad = Ad_inverse(z.W_angle, z.W_t);
      const Eigen::Matrix<double, 14, 19> RH = right_rows<19>(right.hessian, Ad, h);
      const Eigen::Matrix<double, 14, 1> dz =
          -GalerkinBeanieStepMatrix(unknowns_matrix(RH, right.gradient, Ad, h)).solve(residual(right.gradient, Ad));
      const double size = correction_size(dz, z);
      if (!std::isfinite(size)) break;
      apply_correction(z, dz, h);
      ++out.iterations;
      // Converged, or at the equations' rounding noise (small steps h: corrections that stopped
      // shrinking below the noise bound of the engine's confirmation, 1e-8).
      done = size <= tolerance || (size <= 1e-8 && size > 0.5 * previous);
      previous = size;
    }
    out.converged = done;
    if (!done || !sensitivity) return out;

    // dz/d(state) = −(∂E/∂z)^{-1} ∂E/∂state at the solution.
    GalerkinBeanieDerivatives right = galerkin4_beanie_derivatives(par, h, z);
    const Eigen::Matrix3d Ad = Ad_inverse(z.W_angle, z.W_t);
    const Eigen::Matrix<double, 14, 19> RH = right_rows<19>(right.hessian, Ad, h);
    GalerkinBeanieStepMatrix local;
    GalerkinBeanieStepMatrix& lu = carry ? carry->step_matrix : local;  // the next step's chord matrix
    lu.compute(unknowns_matrix(RH, right.gradient, Ad, h));
    if (predicted) {  // the exact Newton correction here must be within the allowance; it is applied
      const Eigen::Matrix<double, 14, 1> dz = -lu.solve(residual(right.gradient, Ad));
      if (!(correction_size(dz, z) <= allowance * tolerance)) {
        done = predicted = false;  // solve on by Newton
        continue;
      }
      apply_correction(z, dz, h);
      // Interval n's carried gradient moved with it to first order (its Hessian; the bracket term
      // re-centres δ at W exp(h ζ)).
      right.gradient += right.hessian.rightCols<14>() * dz;
      right.gradient.segment<3>(10) += (0.5 * h) * (bracket(right.gradient.segment<3>(10)).transpose() * dz.segment<3>(5));
    }
    Eigen::Matrix<double, 14, 19> Js = Eigen::Matrix<double, 14, 19>::Zero();
    Js.topRows<8>() = left_rows<19>(left.hessian, h);
    // The state's δ columns in its η rows: re-centring interval n-1's gradient at W exp(h δ).
    Js.block<3, 3>(5, 10) += (0.5 * h) * bracket(left.gradient.segment<3>(10)).transpose();
    // Interval n through its base node: x_n = x + h v + h² X2, v_n = v + h V1, Ω_n = Ω + h O1.
    Js.col(0) += RH.col(0);
    Js.col(1) += h * RH.col(0) + RH.col(1);
    Js.col(5) += (h * h) * RH.col(0);
    Js.col(6) += h * RH.col(1);
    Js.middleCols<3>(2) += RH.middleCols<3>(2);
    Js.middleCols<3>(7) += h * RH.middleCols<3>(2);
    *sensitivity = -lu.solve(Js);
    if (carry) {
      carry->state = right;
      carry->valid = true;
    }
    return out;
  }
}

namespace {
GalerkinBeanieUnknowns unknowns_relative_to(const GalerkinBeanieInterval& z, const GalerkinBeanieInterval& s, double h) {
  GalerkinBeanieUnknowns u;
  u << z.y.segment<5>(5), log_of(compose(inverse(increment_of(s)), increment_of(z))) / h, z.lambda;
  return u;
}

// The engine flow's predictor (galerkin_flow.hpp, extrapolate): interval n's unknowns
// extrapolated from intervals n-3 (if given: quadratic; else linear), n-2 and n-1, W_n as
// W_{n-1} D with log D extrapolated from the last increments D_k = W_{k-1}^{-1} W_k.
GalerkinBeanieUnknowns extrapolate(const GalerkinBeanieInterval* a0, const GalerkinBeanieInterval& a,
                                   const GalerkinBeanieInterval& b, double h) {
  const GalerkinBeanieInterval& c = a0 ? *a0 : a;
  auto ext = [&](const auto& xa0, const auto& xa, const auto& xb) {
    using V = Eigen::Matrix<double, std::decay_t<decltype(xb)>::RowsAtCompileTime, 1>;
    return a0 ? V(3 * xb - 3 * xa + xa0) : V(2 * xb - xa);
  };
  GalerkinBeanieUnknowns p;
  p.head<5>() = ext(c.y.segment<5>(5), a.y.segment<5>(5), b.y.segment<5>(5));
  const Eigen::Vector3d last = log_of(compose(inverse(increment_of(a)), increment_of(b)));
  p.segment<3>(5) = (a0 ? Eigen::Vector3d(2 * last - log_of(compose(inverse(increment_of(*a0)), increment_of(a)))) : last) / h;
  p.tail<6>() = ext(c.lambda, a.lambda, b.lambda);
  return p;
}
}  // namespace

GalerkinBeanieFlow galerkin4_beanie_flow(const problems::BeanieParameters& par, double h,
                                         const GalerkinBeanieInterval& start, int steps) {
  GalerkinBeanieFlow out;
  out.sensitivity.setIdentity();
  GalerkinBeanieMatrix next;
  GalerkinBeanieSensitivity dz;
  GalerkinBeanieCarry carry;
  GalerkinBeanieInterval s = start, before = start, earlier = start;
  double last_prediction_error = std::numeric_limits<double>::infinity();
  for (int k = 1; k <= steps; ++k) {
    GalerkinBeanieUnknowns p;
    if (k >= 2) p = extrapolate(k >= 3 ? &earlier : nullptr, before, s, h);
    // As the engine: a prediction is taken without iterating when the last one landed within
    // 1/8 of the confirmation's bound (here without the engine's noise term: no condition estimate).
    const bool take = k >= 2 && last_prediction_error <= allowance * tolerance / 8;
    const GalerkinBeanieStep step = galerkin4_beanie_step(par, h, s, &dz, &carry, k >= 2 ? &p : nullptr, take);
    out.iterations += step.iterations;
    if (!step.converged) return out;
    if (k >= 2) {
      const GalerkinBeanieUnknowns landed = unknowns_relative_to(step.next, s, h);
      last_prediction_error = correction_size(landed - p, step.next);
    }
    next.row(0) = out.sensitivity.row(0) + h * out.sensitivity.row(1) + (h * h) * out.sensitivity.row(5);
    next.row(1) = out.sensitivity.row(1) + h * out.sensitivity.row(6);
    next.middleRows<3>(2) = out.sensitivity.middleRows<3>(2) + h * out.sensitivity.middleRows<3>(7);
    next.bottomRows<14>().noalias() = dz * out.sensitivity;
    out.sensitivity.swap(next);
    earlier = before, before = s, s = step.next;
    ++out.steps;
  }
  out.last = s;
  out.converged = true;
  return out;
}

}  // namespace lpshoot::oracles
