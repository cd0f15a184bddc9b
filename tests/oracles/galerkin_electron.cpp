#include "oracles/galerkin_electron.hpp"

#include <Eigen/LU>

#include <cmath>
#include <stdexcept>

namespace lpshoot::oracles {

namespace {
Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& b) {  // cross_matrix(b) y = b × y
  Eigen::Matrix3d K;
  K << 0, -b(2), b(1), b(2), 0, -b(0), -b(1), b(0), 0;
  return K;
}
}  // namespace

// On interval n (τ ∈ [0, 1], t = t_n + h τ), with y = (x_n, v_n, X2, V1):
//   p(τ) = x_n + h τ v_n + h² (X2 H01(τ) + V1 H11(τ)),  H01 = 3τ² − 2τ³,  H11 = τ³ − τ²,
//   p' = v_n + h (X2 H01_τ + V1 H11_τ),  p'' = X2 H01_ττ + V1 H11_ττ,
//   u = m p'' + 2 κ p − (e/c) p' × B = m p'' + 2 κ p + (e/c) [B]× p'   (linear: u = A(τ) y),
// so L~_n = (h/2) Σ_i b_i |A(τ_i) y_n|² = ½ y_nᵀ M y_n with M = h Σ_i b_i A_iᵀ A_i
// (Gauss points τ = ½ ∓ 1/(2√3), weights ½).
//
// Node n's equations are ∂/∂(x_n, v_n) of L~_{n-1} + L~_n with the other nodes held fixed. In the
// increments: x_n moves X2_{n-1} by 1/h² and X2_n by −1/h²; v_n moves V1_{n-1} by 1/h, X2_n by
// −1/h and V1_n by −1/h. With g = M y (the gradient of each L~), scaled by (h², h):
//   E_x = g_{n-1,X2} + h² g_{n,x} − g_{n,X2},   E_v = g_{n-1,V1} + h g_{n,v} − g_{n,X2} − g_{n,V1},
// i.e. E = P_prev M y_{n-1} + P_next M y_n, with y_n = (T y_{n-1}, z) (T: x_n, v_n from interval
// n-1). E = 0 is linear in z: K z = −R y_{n-1}, K = P_next M S, R = P_prev M + P_next M T.
//
// Galerkin 6 (quartic, 3 Gauss points): y gains the bubble a (p += h² a β, β = τ²(1 − τ)²), and
// interval n's bubble equation ∂L~_n/∂a = 0 joins node n's; the unknowns are (X2, V1, a).
namespace {
template <int S>
struct StepSystem {
  static constexpr int ny = 3 * (S + 1), nz = 3 * (S - 1);  // interval coordinates, unknowns
  Eigen::PartialPivLU<Eigen::Matrix<double, nz, nz>> K;
  Eigen::Matrix<double, nz, ny> R;
};

template <int S>
StepSystem<S> step_system(const problems::ElectronModel& model, double h) {
  static_assert(S == 3 || S == 4, "cubic or quartic");
  if (model.quartic != 0.0) throw std::invalid_argument("electron_galerkin oracle: only the linear electron");
  constexpr int ny = StepSystem<S>::ny, nz = StepSystem<S>::nz;
  using Mat = Eigen::Matrix<double, ny, ny>;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity(), C = model.e_over_c * cross_matrix(model.B);
  const double m = model.mass, k2 = 2 * model.potential;
  // Gauss–Legendre on [0, 1]: 2 points (weights ½) or 3 (5/18, 8/18, 5/18).
  const double q = S == 3 ? 0.5 / std::sqrt(3.0) : 0.5 * std::sqrt(0.6);
  const double points[3] = {0.5 - q, S == 3 ? 0.5 + q : 0.5, 0.5 + q};
  const double weights[3] = {S == 3 ? 0.5 : 5.0 / 18, S == 3 ? 0.5 : 8.0 / 18, 5.0 / 18};
  Mat M = Mat::Zero();
  for (int g = 0; g < S - 1; ++g) {
    const double t = points[g], w = weights[g];
    const double H01 = 3 * t * t - 2 * t * t * t, H11 = t * t * t - t * t;
    const double dH01 = 6 * t - 6 * t * t, dH11 = 3 * t * t - 2 * t;
    const double ddH01 = 6 - 12 * t, ddH11 = 6 * t - 2;
    Eigen::Matrix<double, 3, ny> A;
    A.template block<3, 3>(0, 0) = k2 * I;                                                // x_n
    A.template block<3, 3>(0, 3) = k2 * h * t * I + C;                                    // v_n
    A.template block<3, 3>(0, 6) = (m * ddH01 + k2 * h * h * H01) * I + h * dH01 * C;     // X2
    A.template block<3, 3>(0, 9) = (m * ddH11 + k2 * h * h * H11) * I + h * dH11 * C;     // V1
    if constexpr (S == 4) {
      const double B = t * t * (1 - t) * (1 - t), dB = 2 * t - 6 * t * t + 4 * t * t * t, ddB = 2 - 12 * t + 12 * t * t;
      A.template block<3, 3>(0, 12) = (m * ddB + k2 * h * h * B) * I + h * dB * C;       // a
    }
    M.noalias() += (h * w) * A.transpose() * A;
  }
  Eigen::Matrix<double, nz, ny> Pprev = Eigen::Matrix<double, nz, ny>::Zero(), Pnext = Pprev;
  Pprev.template block<3, 3>(0, 6) = I, Pprev.template block<3, 3>(3, 9) = I;
  Pnext.template block<3, 3>(0, 0) = h * h * I, Pnext.template block<3, 3>(0, 6) = -I;
  Pnext.template block<3, 3>(3, 3) = h * I, Pnext.template block<3, 3>(3, 6) = -I, Pnext.template block<3, 3>(3, 9) = -I;
  if constexpr (S == 4) Pnext.template block<3, 3>(6, 12) = I;  // interval n's bubble equation
  Mat T = Mat::Zero();  // x_n = x + h v + h² X2, v_n = v + h V1 of interval n-1
  T.template block<3, 3>(0, 0) = I, T.template block<3, 3>(0, 3) = h * I, T.template block<3, 3>(0, 6) = h * h * I;
  T.template block<3, 3>(3, 3) = I, T.template block<3, 3>(3, 9) = h * I;
  const Eigen::Matrix<double, nz, ny> PM = Pnext * M;
  StepSystem<S> sys;
  sys.K.compute(PM.template rightCols<nz>());
  sys.R = Pprev * M + PM * T;
  return sys;
}
}  // namespace

GalerkinElectronMap electron_galerkin4_step_map(const problems::ElectronModel& model, double h) {
  const StepSystem<3> sys = step_system<3>(model, h);
  return -sys.K.solve(sys.R);
}

GalerkinElectron6Map electron_galerkin6_step_map(const problems::ElectronModel& model, double h) {
  const StepSystem<4> sys = step_system<4>(model, h);
  return -sys.K.solve(sys.R);
}

Eigen::Matrix<double, 6, 1> electron_galerkin4_step(const problems::ElectronModel& model, double h,
                                                    const GalerkinElectronState& state,
                                                    GalerkinElectronMap* sensitivity) {
  const StepSystem<3> sys = step_system<3>(model, h);
  if (!sensitivity) return -sys.K.solve(sys.R * state);
  *sensitivity = -sys.K.solve(sys.R);
  return *sensitivity * state;
}

}  // namespace lpshoot::oracles
