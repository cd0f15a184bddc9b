#include "oracles/analytic_steps.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <cmath>

namespace lpshoot::oracles {

namespace {
Eigen::Vector3d electron_U(const Electron& e, const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                           const Eigen::Vector3d& x2, double h) {
  return e.mass * (x2 - 2 * x1 + x0) / (h * h) + 2 * e.potential * x0 - e.e_over_c * ((x1 - x0) / h).cross(e.B);
}
Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& b) {
  Eigen::Matrix3d K;
  K << 0, -b(2), b(1), b(2), 0, -b(0), -b(1), b(0), 0;
  return K;
}

// The beanie constraints' rotation Rot(β) = R(-β) (exact) or I - βJ (paper) and its first two
// β-derivatives: -J R(-β), -R(-β); -J, 0.
struct ConstraintRotation {
  bool exact;
  Eigen::Matrix2d J = (Eigen::Matrix2d() << 0, -1, 1, 0).finished();
  explicit ConstraintRotation(const BeanieControl& b) : exact(b.variant == problems::BeanieConstraints::ExactRotation) {}
  Eigen::Matrix2d rot(double beta) const {
    return exact ? SO2::rotation(-beta) : Eigen::Matrix2d(Eigen::Matrix2d::Identity() - beta * J);
  }
  Eigen::Matrix2d drot(double beta) const { return exact ? Eigen::Matrix2d(-J * SO2::rotation(-beta)) : Eigen::Matrix2d(-J); }
  Eigen::Matrix2d ddrot(double beta) const { return exact ? Eigen::Matrix2d(-SO2::rotation(-beta)) : Eigen::Matrix2d::Zero(); }
};
}  // namespace

Eigen::Vector3d electron_stencil_residual(const Electron& e, const std::array<Eigen::Vector3d, 5>& xs, double h) {
  // Component i of node j = n-2 .. n+2 is xs[j - n + 2](i).
  auto x = [&](int i, int off) { return xs[off + 2](i); };
  const double m = e.mass, w = e.e_over_c * e.B(2) / m, k = e.potential;
  auto D4 = [&](int i) { return (x(i, 2) - 4 * x(i, 1) + 6 * x(i, 0) - 4 * x(i, -1) + x(i, -2)) / std::pow(h, 4); };
  auto D3b = [&](int i) { return (x(i, 1) - 3 * x(i, 0) + 3 * x(i, -1) - x(i, -2)) / std::pow(h, 3); };
  auto D3f = [&](int i) { return (x(i, 2) - 3 * x(i, 1) + 3 * x(i, 0) - x(i, -1)) / std::pow(h, 3); };
  auto D2 = [&](int i, int c) { return (x(i, c + 1) - 2 * x(i, c) + x(i, c - 1)) / (h * h); };
  auto D1b = [&](int i) { return (x(i, 0) - x(i, -1)) / h; };
  auto D1f = [&](int i) { return (x(i, 1) - x(i, 0)) / h; };
  // The paper's φ = |x|^2 gives the 2/m and 4/m^2 coefficients; a general potential κ|x|^2
  // scales them by κ and κ^2.
  auto common = [&](int i) { return -(2 * k / m) * (D2(i, -1) + D2(i, 1)) - 4 * k * k * x(i, 0) / (m * m); };
  Eigen::Vector3d r;
  r(0) = D4(0) - (w * (D3b(1) + D3f(1)) + w * w * D2(0, 0) + common(0) + (2 * k * w / m) * (D1b(1) + D1f(1)));
  r(1) = D4(1) - (-w * (D3b(0) + D3f(0)) + w * w * D2(1, 0) + common(1) - (2 * k * w / m) * (D1b(0) + D1f(0)));
  r(2) = D4(2) - common(2);
  return r;
}

Eigen::Vector3d electron_analytic_residual(const Electron& e, const std::array<Eigen::Vector3d, 5>& x, double h) {
  const Eigen::Vector3d U0 = electron_U(e, x[0], x[1], x[2], h);  // U_{n-2}
  const Eigen::Vector3d U1 = electron_U(e, x[1], x[2], x[3], h);  // U_{n-1}
  const Eigen::Vector3d U2 = electron_U(e, x[2], x[3], x[4], h);  // U_n
  return (e.mass / h) * (U0 - 2 * U1 + U2) + 2 * e.potential * h * U2 + e.e_over_c * e.B.cross(U2 - U1);
}

Eigen::Vector3d electron_analytic_step(const Electron& e, const std::array<Eigen::Vector3d, 4>& x, double h) {
  // [(m/h + 2κh) I + (e/c)[B×]] U_n = (m/h)(2U_{n-1} - U_{n-2}) + (e/c) B × U_{n-1}.
  const Eigen::Vector3d U0 = electron_U(e, x[0], x[1], x[2], h);
  const Eigen::Vector3d U1 = electron_U(e, x[1], x[2], x[3], h);
  const Eigen::Matrix3d A = (e.mass / h + 2 * e.potential * h) * Eigen::Matrix3d::Identity() +
                            e.e_over_c * cross_matrix(e.B);
  const Eigen::Vector3d rhs = (e.mass / h) * (2 * U1 - U0) + e.e_over_c * e.B.cross(U1);
  const Eigen::Vector3d U2 = A.inverse() * rhs;
  // U_n = m (x_{n+2} - 2x_{n+1} + x_n)/h^2 + 2κ x_n - (e/c) ((x_{n+1} - x_n)/h) × B.
  const Eigen::Vector3d known = 2 * e.potential * x[2] - e.e_over_c * ((x[3] - x[2]) / h).cross(e.B);
  return (h * h / e.mass) * (U2 - known) + 2 * x[3] - x[2];
}

// With X = [B×], β = e/c, a = m/h²: U(x_i, x_{i+1}, x_{i+2}) = C0 x_i + C1 x_{i+1} + C2 x_{i+2},
// C0 = (a + 2κ) I - (β/h) X, C1 = -2a I + (β/h) X, C2 = a I; the right-hand side is
// P U_{n-1} - Q U_{n-2} with P = (2m/h) I + β X, Q = (m/h) I; "known" = 2κ x_n + (β/h) X (x_{n+1} - x_n).
Eigen::Matrix<double, 3, 12> electron_paper_step_map(const Electron& e, double h) {
  using Eigen::Matrix3d;
  const Matrix3d I = Matrix3d::Identity(), X = cross_matrix(e.B);
  const double a = e.mass / (h * h), beta = e.e_over_c, kappa = e.potential;
  const Matrix3d C0 = (a + 2 * kappa) * I - (beta / h) * X, C1 = -2 * a * I + (beta / h) * X, C2 = a * I;
  const Matrix3d P = (2 * e.mass / h) * I + beta * X, Q = (e.mass / h) * I;
  const Matrix3d A_inverse = ((e.mass / h + 2 * kappa * h) * I + beta * X).inverse();
  const double s = h * h / e.mass;
  Eigen::Matrix<double, 3, 12> Phi;
  Phi.block<3, 3>(0, 0) = s * A_inverse * (-Q * C0);
  Phi.block<3, 3>(0, 3) = s * A_inverse * (P * C0 - Q * C1);
  Phi.block<3, 3>(0, 6) = s * (A_inverse * (P * C1 - Q * C2) - 2 * kappa * I + (beta / h) * X) - I;
  Phi.block<3, 3>(0, 9) = s * (A_inverse * (P * C2) - (beta / h) * X) + 2 * I;
  return Phi;
}

// Derivation (window j: ψ_j, ψ_{j+1}, ψ_{j+2}, g~_j = (ω_j, t_j), g~_{j+1}; β_j = ω_j - cΔψ_j):
//   u_j = μ Δ²ψ_j / h^2 + V'(ψ_{j+1}),  L^_j = (h/2) u_j^2,
//   χ_j = ((t_{j+1} - Rot(β_j) t_j)/h, (ω_{j+1} - ω_j)/h), Rot(β) = R(-β) or I - βJ.
// The connection moves ω_{n-1} by +c δψ and ω_n by -c δψ, leaving β unchanged, so the χ terms
// of the ψ-equation cancel except the ω-differences:
//   E_ψ = (μ/h)(u_{n-2} - 2u_{n-1} + u_n) + h V''(ψ_n) u_{n-1} + (c/h)(λ3^{n-2} - 2λ3^{n-1} + λ3^n).
// With μ^R(F) = (∂F/∂t, ∂F/∂ω + ∂F/∂t · J t) for SE(2) = (ω, t):
//   P_j = (λ12^{j-1} - Rot(β_j)^T λ12^j)/h,  Q_j = (λ3^{j-1} - λ3^j)/h - λ12^j · Rot'(β_j) t_j / h,
//   M_j = (P_j, Q_j + P_j · J t_j), and E_η = Ad*_{W_{n-1}} M_{n-1} - M_n with W_{n-1} = (β_{n-1}, t_{n-1}).
StepUnknowns<BeanieControl> beanie_control_analytic_step(const BeanieControl& b, const FlowState<BeanieControl>& s,
                                                         double h) {
  using Eigen::Matrix2d;
  using Eigen::Vector2d;
  const BeanieParameters& par = b.par;
  const double c = par.c(), mu = par.mu();
  const ConstraintRotation R(b);
  const Matrix2d& J = R.J;
  auto rot = [&](double beta) { return R.rot(beta); };
  auto drot = [&](double beta) { return R.drot(beta); };
  auto psi = [&](int i) { return s.p[i](0); };  // ψ_{n-2+i}
  auto ddV = [&](double x) { return par.amplitude * std::cos(x); };
  auto u = [&](int i) { return mu * (psi(i + 2) - 2 * psi(i + 1) + psi(i)) / (h * h) + par.dV(psi(i + 1)); };
  // Local increments: s.g[0] = g~_{n-2}, s.g[1] = g~_{n-1}, s.g[2] = g~_n; s.lam[0] = λ^{n-2}, s.lam[1] = λ^{n-1}.
  auto beta = [&](int i) { return s.g[i].angle - c * (psi(i + 1) - psi(i)); };
  const Vector2d l12_0 = s.lam[0].head<2>(), l12_1 = s.lam[1].head<2>();
  const double l3_0 = s.lam[0](2), l3_1 = s.lam[1](2);

  // M_{n-1} (increment g~_{n-1}: windows n-2 and n-1).
  const double b1 = beta(1), b2 = beta(2);
  const Vector2d t1 = s.g[1].t, t2 = s.g[2].t;
  const Vector2d P1 = (l12_0 - rot(b1).transpose() * l12_1) / h;
  const double Q1 = (l3_0 - l3_1) / h - l12_1.dot(drot(b1) * t1) / h;
  const Eigen::Vector3d M1(P1(0), P1(1), Q1 + P1.dot(J * t1));
  // Target M_n = Ad*_{W_{n-1}} M_{n-1}, W_{n-1} = (β_{n-1}, t_{n-1}).
  const Eigen::Vector3d Mn = SE2::Ad<double>({b1, t1}).transpose() * M1;
  const Vector2d Pn = Mn.head<2>();
  const double Qn = Mn(2) - Pn.dot(J * t2);
  StepUnknowns<BeanieControl> z;
  const Vector2d l12_n = rot(b2).transpose().inverse() * (l12_1 - h * Pn);
  const double Gn = -l12_n.dot(drot(b2) * t2) / h;
  const double l3_n = l3_1 + h * (Gn - Qn);
  z.lam << l12_n, l3_n;

  const double un = 2 * u(1) - u(0) - (h * h / mu) * ddV(psi(2)) * u(1) - (c / mu) * (l3_0 - 2 * l3_1 + l3_n);
  z.p(0) = h * h * (un - par.dV(psi(3))) / mu + 2 * psi(3) - psi(2);
  z.g = {s.g[2].angle, rot(b2) * t2};
  return z;
}

// The tangent-linear form of the step above, line by line (no automatic differentiation). Each
// quantity x carries dx, its row of derivatives in the state's 19 tangent coordinates
// (FlowState's offsets): δψ_{n-2+i} moves ψ_i; g~ -> g~ exp(δ) moves an increment's angle by δ_ω
// and its translation by R(angle) δ_t; δλ moves λ. Derivatives used:
//   d/dβ R(-β) = -J R(-β), d²/dβ² R(-β) = -R(-β);  d/dβ (I - βJ) = -J;  d/dω R(ω) = J R(ω);
//   Ad_{(β, t)}ᵀ M = (R(β)ᵀ M12, M3 - (J t)·M12)  (SE2::Ad);  V = A (1 - cos): V' = A sin, ...
// The result ζ of g~_{n+1} = (ω_n, Rot(β_n) t_n) is (R(ω_n)ᵀ dt, dω) in the same right coordinates.
StepUnknowns<BeanieControl> beanie_control_analytic_step(const BeanieControl& b, const FlowState<BeanieControl>& s,
                                                         double h, BeanieStepSensitivity& dz) {
  using Eigen::Matrix2d;
  using Eigen::Vector2d;
  using FS = FlowState<BeanieControl>;
  constexpr int ns = Dims<BeanieControl>::state;
  using Row = Eigen::Matrix<double, 1, ns>;
  using Rows2 = Eigen::Matrix<double, 2, ns>;
  const BeanieParameters& par = b.par;
  const double c = par.c(), mu = par.mu(), A = par.amplitude;
  const ConstraintRotation R(b);
  const Matrix2d& J = R.J;
  auto rot = [&](double beta) { return R.rot(beta); };
  auto drot = [&](double beta) { return R.drot(beta); };
  auto ddrot = [&](double beta) { return R.ddrot(beta); };
  auto unit = [](int col) {
    Row e = Row::Zero();
    e(col) = 1.0;
    return e;
  };

  // Inputs and their derivative rows.
  double psi[4];
  Row dpsi[4];
  for (int i = 0; i < 4; ++i) psi[i] = s.p[i](0), dpsi[i] = unit(FS::p_offset(i));
  Row domega[3];
  Rows2 dt[3];
  for (int i = 0; i < 3; ++i) {
    domega[i] = unit(FS::g_offset(i) + 2);
    Rows2 delta = Rows2::Zero();
    delta(0, FS::g_offset(i)) = 1.0, delta(1, FS::g_offset(i) + 1) = 1.0;
    dt[i] = SO2::rotation(s.g[i].angle) * delta;
  }
  Rows2 dl12[2];
  Row dl3[2];
  for (int j = 0; j < 2; ++j) {
    dl12[j] = Rows2::Zero();
    dl12[j](0, FS::lam_offset(j)) = 1.0, dl12[j](1, FS::lam_offset(j) + 1) = 1.0;
    dl3[j] = unit(FS::lam_offset(j) + 2);
  }
  const Vector2d l12_0 = s.lam[0].head<2>(), l12_1 = s.lam[1].head<2>();
  const double l3_0 = s.lam[0](2), l3_1 = s.lam[1](2);

  // u_i = μ Δ²ψ_i / h² + V'(ψ_{i+1}), i = 0, 1.
  double u[2];
  Row du[2];
  for (int i = 0; i < 2; ++i) {
    u[i] = mu * (psi[i + 2] - 2 * psi[i + 1] + psi[i]) / (h * h) + par.dV(psi[i + 1]);
    du[i] = (mu / (h * h)) * (dpsi[i + 2] - 2 * dpsi[i + 1] + dpsi[i]) + A * std::cos(psi[i + 1]) * dpsi[i + 1];
  }
  // β_i = ω_i - c (ψ_{i+1} - ψ_i), i = 1, 2.
  const double b1 = s.g[1].angle - c * (psi[2] - psi[1]), b2 = s.g[2].angle - c * (psi[3] - psi[2]);
  const Row db1 = domega[1] - c * (dpsi[2] - dpsi[1]), db2 = domega[2] - c * (dpsi[3] - dpsi[2]);
  const Vector2d t1 = s.g[1].t, t2 = s.g[2].t;

  // M_{n-1} = (P1, Q1 + P1 · J t1).
  const Matrix2d R1 = rot(b1), dR1 = drot(b1);
  const Vector2d P1 = (l12_0 - R1.transpose() * l12_1) / h;
  const Rows2 dP1 = (dl12[0] - (dR1.transpose() * l12_1) * db1 - R1.transpose() * dl12[1]) / h;
  const Vector2d dR1t1 = dR1 * t1;
  const double Q1 = (l3_0 - l3_1) / h - l12_1.dot(dR1t1) / h;
  const Row dQ1 = (dl3[0] - dl3[1]) / h -
                  (dR1t1.transpose() * dl12[1] + l12_1.dot(ddrot(b1) * t1) * db1 + l12_1.transpose() * dR1 * dt[1]) / h;
  const double M1_3 = Q1 + P1.dot(J * t1);
  const Row dM1_3 = dQ1 + (J * t1).transpose() * dP1 + P1.transpose() * J * dt[1];

  // M_n = Ad_{(β1, t1)}ᵀ M_{n-1}.
  const Matrix2d Rb1 = SO2::rotation(b1);
  const Vector2d Pn = Rb1.transpose() * P1;
  const Rows2 dPn = -(Rb1.transpose() * J * P1) * db1 + Rb1.transpose() * dP1;
  const double Mn_3 = M1_3 - (J * t1).dot(P1);
  const Row dMn_3 = dM1_3 - P1.transpose() * J * dt[1] - (J * t1).transpose() * dP1;
  const double Qn = Mn_3 - Pn.dot(J * t2);
  const Row dQn = dMn_3 - (J * t2).transpose() * dPn - Pn.transpose() * J * dt[2];

  // λ12^n = Rot(β2)^{-T} (λ12^{n-1} - h Pn).
  const Matrix2d R2 = rot(b2), dR2 = drot(b2);
  const Eigen::PartialPivLU<Matrix2d> R2T(R2.transpose());
  const Vector2d l12_n = R2T.solve(l12_1 - h * Pn);
  const Rows2 dl12_n = R2T.solve(dl12[1] - h * dPn - (dR2.transpose() * l12_n) * db2);
  // λ3^n = λ3^{n-1} + h (Gn - Qn), Gn = -λ12^n · Rot'(β2) t2 / h.
  const Vector2d dR2t2 = dR2 * t2;
  const double Gn = -l12_n.dot(dR2t2) / h;
  const Row dGn = -(dR2t2.transpose() * dl12_n + l12_n.dot(ddrot(b2) * t2) * db2 + l12_n.transpose() * dR2 * dt[2]) / h;
  const double l3_n = l3_1 + h * (Gn - Qn);
  const Row dl3_n = dl3[1] + h * (dGn - dQn);

  // u_n, then ψ_{n+2} = h² (u_n - V'(ψ_{n+1})) / μ + 2 ψ_{n+1} - ψ_n.
  const double ddV2 = A * std::cos(psi[2]);
  const double un = 2 * u[1] - u[0] - (h * h / mu) * ddV2 * u[1] - (c / mu) * (l3_0 - 2 * l3_1 + l3_n);
  const Row dun = 2 * du[1] - du[0] - (h * h / mu) * (ddV2 * du[1] - A * std::sin(psi[2]) * u[1] * dpsi[2]) -
                  (c / mu) * (dl3[0] - 2 * dl3[1] + dl3_n);

  StepUnknowns<BeanieControl> z;
  z.p(0) = h * h * (un - par.dV(psi[3])) / mu + 2 * psi[3] - psi[2];
  z.g = {s.g[2].angle, R2 * t2};
  z.lam << l12_n, l3_n;
  dz.row(0) = (h * h / mu) * (dun - A * std::cos(psi[3]) * dpsi[3]) + 2 * dpsi[3] - dpsi[2];
  dz.middleRows<2>(1) = SO2::rotation(z.g.angle).transpose() * (dR2t2 * db2 + R2 * dt[2]);
  dz.row(3) = domega[2];
  dz.middleRows<2>(4) = dl12_n;
  dz.row(6) = dl3_n;
  return z;
}

Eigen::Vector4d beanie_unreduced_step(const BeanieParameters& par, const Eigen::Vector4d& q_prev,
                                      const Eigen::Vector4d& q, double h) {
  const Eigen::Vector4d dq = q - q_prev;
  const double c = par.c();
  const double dpsi = dq(3) - h * h * par.dV(q(3)) / par.mu();
  const double s = dq(2) + c * dq(3);  // Δθ + cΔψ, conserved
  Eigen::Vector4d next;
  next << q(0) + dq(0), q(1) + dq(1), q(2) + s - c * dpsi, q(3) + dpsi;
  return next;
}

}  // namespace lpshoot::oracles
