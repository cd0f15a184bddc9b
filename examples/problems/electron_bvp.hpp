// The electron's minimum-energy transfer as a boundary value problem: x and x' prescribed at
// both ends (METHOD.md §6.1), mapped to nodes 0, 1 and N-1, N by the chosen closure.
#pragma once

#include "electron.hpp"

#include <lpshoot/shooting/shooting.hpp>

namespace lpshoot::problems {

struct ElectronBoundary {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

inline BoundaryValueProblem<Electron> electron_bvp(const Electron& e, double T, int N, const ElectronBoundary& start,
                                                   const ElectronBoundary& end, Closure closure) {
  BoundaryValueProblem<Electron> bvp{e, N, T, {}};
  for (int i = 0; i < 3; ++i) {
    const std::string x = "x" + std::to_string(i + 1);
    bvp.shape_with_velocity(End::Initial, i, start.position(i), start.velocity(i), closure, "initial " + x);
    bvp.shape_with_velocity(End::Terminal, i, end.position(i), end.velocity(i), closure, "terminal " + x);
  }
  return bvp;
}

// Cubic Hermite interpolation of the boundary data on the grid.
inline ShootingGuess<Electron> electron_guess(const BoundaryValueProblem<Electron>& bvp, const ElectronBoundary& start,
                                              const ElectronBoundary& end) {
  ShootingGuess<Electron> guess;
  Trajectory<Electron>& tr = guess.trajectory;
  tr.h = bvp.h();
  for (int n = 0; n <= bvp.N; ++n) {
    const double s = double(n) / bvp.N, T = bvp.T;
    const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
    const double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
    tr.p.push_back(h00 * start.position + h10 * T * start.velocity + h01 * end.position + h11 * T * end.velocity);
  }
  tr.g.assign(bvp.N, Trivial::identity<double>());
  tr.lam.assign(bvp.N - Electron::order + 1, Vec<double, 0>());
  return guess;
}

}  // namespace lpshoot::problems
