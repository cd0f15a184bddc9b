// The electron's minimum-energy transfer as a boundary value problem: x and x' prescribed at
// both ends (METHOD.md §6.1), mapped to nodes 0, 1 and N-1, N by the chosen closure. An end may
// leave x' free (natural condition at the second node) or x and x' free (natural at both).
#pragma once

#include "electron.hpp"

#include <lpshoot/shooting/shooting.hpp>

#include <stdexcept>

namespace lpshoot::problems {

struct ElectronBoundary {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  bool free_position = false;  // requires free_velocity
  bool free_velocity = false;
};

inline BoundaryValueProblem<Electron> electron_bvp(const Electron& e, double T, int N, const ElectronBoundary& start,
                                                   const ElectronBoundary& end, Closure closure) {
  BoundaryValueProblem<Electron> bvp{e, N, T, {}};
  for (End e : {End::Initial, End::Terminal}) {
    const ElectronBoundary& b = e == End::Initial ? start : end;
    const std::string side = e == End::Initial ? "initial " : "terminal ";
    if (b.free_position && !b.free_velocity) throw std::invalid_argument(side + "velocity is given without the position");
    for (int i = 0; i < 3; ++i) {
      const std::string x = side + "x" + std::to_string(i + 1);
      if (!b.free_velocity) {
        bvp.shape_with_velocity(e, i, b.position(i), b.velocity(i), closure, x);
        continue;
      }
      if (b.free_position)
        bvp.natural(e, 0, i, x + " (natural)");
      else
        bvp.fix_shape(e, 0, i, b.position(i), x);
      bvp.natural(e, 1, i, x + "' (natural)");
    }
  }
  return bvp;
}

// Cubic Hermite interpolation of the boundary data on the grid (a free position: the other
// end's; a free velocity: zero).
inline ShootingGuess<Electron> electron_guess(const BoundaryValueProblem<Electron>& bvp, const ElectronBoundary& start,
                                              const ElectronBoundary& end) {
  ShootingGuess<Electron> guess;
  Trajectory<Electron>& tr = guess.trajectory;
  const Eigen::Vector3d x0 = start.free_position ? (end.free_position ? Eigen::Vector3d::Zero() : end.position) : start.position;
  const Eigen::Vector3d xT = end.free_position ? x0 : end.position;
  const Eigen::Vector3d v0 = start.free_velocity ? Eigen::Vector3d::Zero() : start.velocity;
  const Eigen::Vector3d vT = end.free_velocity ? Eigen::Vector3d::Zero() : end.velocity;
  tr.h = bvp.h();
  for (int n = 0; n <= bvp.N; ++n) {
    const double s = double(n) / bvp.N, T = bvp.T;
    const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
    const double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
    tr.p.push_back(h00 * x0 + h10 * T * v0 + h01 * xT + h11 * T * vT);
  }
  tr.g.assign(bvp.N, Trivial::identity<double>());
  tr.lam.assign(bvp.N - Electron::order + 1, Vec<double, 0>());
  return guess;
}

// The same transfer for a Galerkin scheme of degree S (order 2S - 2): positions and velocities
// are node values, imposed exactly; a free one gets its natural condition.
template <int S>
using ElectronGalerkin = Galerkin<ElectronModel, S>;

template <int S>
GalerkinBVP<ElectronGalerkin<S>> electron_galerkin_bvp(const ElectronModel& model, double T, int N,
                                                       const ElectronBoundary& start, const ElectronBoundary& end) {
  using B = GalerkinBVP<ElectronGalerkin<S>>;
  B bvp{model, N, T, {}};
  for (End e : {End::Initial, End::Terminal}) {
    const ElectronBoundary& b = e == End::Initial ? start : end;
    const std::string side = e == End::Initial ? "initial " : "terminal ";
    if (b.free_position && !b.free_velocity) throw std::invalid_argument(side + "velocity is given without the position");
    for (int i = 0; i < 3; ++i) {
      const std::string x = side + "x" + std::to_string(i + 1);
      if (b.free_position)
        bvp.natural(e, B::x_component(i), x + " (natural)");
      else
        bvp.fix(e, B::x_component(i), b.position(i), x);
      if (b.free_velocity)
        bvp.natural(e, B::v_component(i), x + "' (natural)");
      else
        bvp.fix(e, B::v_component(i), b.velocity(i), x + "'");
    }
  }
  return bvp;
}

// Cubic Hermite interpolation of the boundary data over [0, T], as node states and increments.
template <int S>
GalerkinGuess<ElectronGalerkin<S>> electron_galerkin_guess(const GalerkinBVP<ElectronGalerkin<S>>& bvp,
                                                           const ElectronBoundary& start, const ElectronBoundary& end) {
  const auto nodal = electron_guess(electron_bvp(Electron{}, bvp.T, bvp.N, start, end, Closure::SecondOrder), start, end);
  const Eigen::Vector3d v0 = start.free_velocity ? Eigen::Vector3d::Zero() : start.velocity;
  const Eigen::Vector3d vT = end.free_velocity ? Eigen::Vector3d::Zero() : end.velocity;
  const Eigen::Vector3d x0 = nodal.trajectory.p.front(), xT = nodal.trajectory.p.back();
  const double T = bvp.T, h = bvp.h();
  auto velocity = [&](double t) {  // derivative of the Hermite cubic
    const double s = t / T;
    const double d00 = (6 * s * s - 6 * s) / T, d10 = 3 * s * s - 4 * s + 1, d01 = (-6 * s * s + 6 * s) / T, d11 = 3 * s * s - 2 * s;
    return Eigen::Vector3d(d00 * x0 + d10 * v0 + d01 * xT + d11 * vT);
  };
  GalerkinGuess<ElectronGalerkin<S>> guess;
  auto& tr = guess.trajectory;
  tr.h = h;
  for (int n = 0; n < bvp.N; ++n) {
    Interval<ElectronGalerkin<S>, double> iv;
    iv.x = nodal.trajectory.p[n];
    iv.v = velocity(n * h);
    iv.X2 = (nodal.trajectory.p[n + 1] - iv.x - h * iv.v) / (h * h);
    iv.V1 = (velocity((n + 1) * h) - iv.v) / h;
    iv.w.setZero();
    tr.intervals.push_back(iv);
  }
  return guess;
}

}  // namespace lpshoot::problems
