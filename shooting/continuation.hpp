// Initial guesses from previous solutions: resampling onto another grid (warm start from a
// coarser solve) and continuation in a scalar parameter (horizon, field strength, potential
// scale), with the parameter step adapted to the solver's success.
#pragma once

#include "galerkin_resample.hpp"
#include "shooting.hpp"

#include <functional>

namespace lpshoot {

// A guess on N nodes from a solved trajectory on another grid of the same horizon: p and λ
// interpolated linearly in time, increments g~ = exp((h_new/h_old) log(g~_old)) at the nearest
// old interval (they scale with the step), g_0 kept.
template <class P>
ShootingGuess<P> resample(const ShootingResult<P>& from, int N) {
  using G = typename P::Group;
  constexpr int k = P::order;
  const Trajectory<P>& old = from.trajectory;
  const double T = old.N() * old.h, h = T / N, ratio = h / old.h;
  ShootingGuess<P> guess;
  Trajectory<P>& tr = guess.trajectory;
  tr.h = h;
  auto interp = [&](const auto& v, double t) {
    const double s = std::clamp(t / old.h, 0.0, double(v.size() - 1));
    const int i = std::min(static_cast<int>(s), static_cast<int>(v.size()) - 2);
    const double w = s - i;
    return ((1 - w) * v[i] + w * v[i + 1]).eval();
  };
  for (int n = 0; n <= N; ++n) tr.p.push_back(interp(old.p, n * h));
  for (int n = 0; n < N; ++n) {
    const int i = std::min(static_cast<int>((n + 0.5) * h / old.h), old.N() - 1);
    tr.g.push_back(G::template exp<double>(typename G::template Tangent<double>(ratio * G::log(old.g[i]))));
  }
  for (int n = 0; n <= N - k; ++n) {
    if constexpr (P::num_constraints > 0)
      tr.lam.push_back(old.lam.size() > 1 ? interp(old.lam, n * h) : old.lam.front());
    else
      tr.lam.push_back(Vec<double, 0>());
  }
  guess.g0 = from.g.empty() ? G::template identity<double>() : from.g.front();
  return guess;
}

// The same on a Galerkin trajectory: the old curves restricted to the new intervals (refining) or
// sampled at the new nodes (coarsening), multipliers interpolated (galerkin_resample.hpp).
template <class C, int S, int Q>
GalerkinGuess<Galerkin<C, S, Q>> resample(const C& model, const ShootingResult<Galerkin<C, S, Q>>& from, int N) {
  GalerkinGuess<Galerkin<C, S, Q>> guess;
  guess.trajectory = resample_trajectory(model, from.trajectory, N);
  return guess;
}

template <class P>
ShootingGuess<P> as_guess(const ShootingResult<P>& r) {
  ShootingGuess<P> g;
  g.trajectory = r.trajectory;
  g.g0 = r.g.front();
  return g;
}

template <class C, int S, int Q>
GalerkinGuess<Galerkin<C, S, Q>> as_guess(const ShootingResult<Galerkin<C, S, Q>>& r) {
  GalerkinGuess<Galerkin<C, S, Q>> g;
  g.trajectory = r.trajectory;
  return g;
}

struct ContinuationOptions {
  double initial_step = 0.25;  // as a fraction of |to - from|
  double min_step = 1e-4;      // same units; smaller steps give up
  int max_solves = 200;
  // Called after each solve with the parameter tried, whether it converged and its iterations.
  std::function<void(double, bool, int)> on_solve;
};

template <class P>
struct ContinuationResult {
  ShootingResult<P> result;       // at the last parameter reached
  double parameter = 0;           // the last parameter solved
  std::vector<double> path;       // parameters solved, in order
  int solves = 0;
  bool reached = false;
};

// Solves make(s) for s from `from` to `to`, each solve starting from the previous solution; a
// failed step is halved (the step tried: the last one is cut short to end at `to`), a success
// lets the step grow by 1.5.
template <class P>
ContinuationResult<P> continuation(const std::function<typename SchemeFor<P>::BVP(double)>& make, double from, double to,
                                   const typename SchemeFor<P>::Guess& guess, const ShootingOptions& opt = {},
                                   const ContinuationOptions& copt = {}) {
  ContinuationResult<P> out;
  const double span = to - from;
  out.result = solve_bvp(make(from), guess, opt);
  ++out.solves;
  if (copt.on_solve) copt.on_solve(from, out.result.ok(), out.result.iterations);
  if (!out.result.ok()) {
    out.result.message = "continuation could not start at " + std::to_string(from) + ": " + out.result.message;
    return out;
  }
  out.parameter = from;
  out.path.push_back(from);
  double step = copt.initial_step * span;
  while (out.parameter != to && out.solves < copt.max_solves) {
    const double next = std::abs(to - out.parameter) <= std::abs(step) ? to : out.parameter + step;
    auto r = solve_bvp(make(next), as_guess(out.result), opt);
    ++out.solves;
    if (copt.on_solve) copt.on_solve(next, r.ok(), r.iterations);
    const double tried = next - out.parameter;  // the step, or what was left of the way to `to`
    if (r.ok()) {
      out.result = std::move(r);
      out.parameter = next;
      out.path.push_back(next);
      step *= 1.5;
    } else {
      step = 0.5 * tried;  // not the uncut step: halved, it could reach `to` again
      if (std::abs(step) < copt.min_step * std::abs(span)) {
        out.result.status = r.status;
        out.result.message = "continuation stalled at " + std::to_string(out.parameter) + " (step below " +
                             std::to_string(copt.min_step * std::abs(span)) + "): " + r.message;
        return out;
      }
    }
  }
  out.reached = out.parameter == to;
  if (!out.reached) out.result.message = "continuation stopped after " + std::to_string(out.solves) + " solves";
  return out;
}

}  // namespace lpshoot
