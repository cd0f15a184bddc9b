// The electron's Galerkin 4 step (METHOD.md §9, cubic Hermite, 2 Gauss points) and Galerkin 6
// step (below) derived by hand: the independent oracles for the engine's derived Galerkin steps
// and their sensitivities, and the hand-written baselines of bench/bench_galerkin_step.cpp and
// bench/bench_ratios.cpp. Only the linear electron (quartic = 0):
// its ℓ = ½|u|² with u linear in the jet makes the step a linear map, solved in closed form.
#pragma once

#include <lpshoot/problems/electron.hpp>

namespace lpshoot::oracles {

// An interval's coordinates in the engine's Galerkin order (galerkin.hpp): (x, v, X2, V1), with
// x_{n+1} = x_n + h v_n + h² X2 and v_{n+1} = v_n + h V1.
using GalerkinElectronState = Eigen::Matrix<double, 12, 1>;
// The step: interval n's increments (X2, V1) = Φ · (interval n-1's coordinates).
using GalerkinElectronMap = Eigen::Matrix<double, 6, 12>;

// Φ for step h. Requires model.quartic == 0 (otherwise the step is not linear).
GalerkinElectronMap electron_galerkin4_step_map(const problems::ElectronModel& model, double h);

// One step from interval n-1 (`state`): interval n's (X2, V1) and, if `sensitivity` is given,
// its derivative with respect to `state` (Φ itself: the step is linear).
Eigen::Matrix<double, 6, 1> electron_galerkin4_step(const problems::ElectronModel& model, double h,
                                                    const GalerkinElectronState& state,
                                                    GalerkinElectronMap* sensitivity = nullptr);

// Galerkin 6 (quartic, one bubble a per component, 3 Gauss points): an interval's coordinates
// (x, v, X2, V1, a) and the step (X2, V1, a) of interval n = Φ · (interval n-1), the engine's
// ElectronGalerkin<4> layout. Requires model.quartic == 0.
using GalerkinElectron6State = Eigen::Matrix<double, 15, 1>;
using GalerkinElectron6Map = Eigen::Matrix<double, 9, 15>;
GalerkinElectron6Map electron_galerkin6_step_map(const problems::ElectronModel& model, double h);

}  // namespace lpshoot::oracles
