// The paper's nodal windows for a problem given by its continuous model (issue 13): the
// discrete problem PaperWindows<Model> (core/paper_windows.hpp, the symmetric jet, order 2), its
// boundary conditions from the scene, a guess, the solve and the same columns as the Galerkin
// runs. Included by model_problem.hpp only.
#pragma once

#include "model_problem.hpp"

namespace lpshoot::app {

template <class Model, int MaxOrder, bool DerivedPaper>
BoundaryValueProblem<typename ModelProblem<Model, MaxOrder, DerivedPaper>::PaperScheme>
ModelProblem<Model, MaxOrder, DerivedPaper>::paper_boundary_value_problem(const Scene& s) const {
  using P = PaperScheme;
  BoundaryValueProblem<P> bvp{P{model(s)}, s.N, s.T, {}};
  const ProblemDescriptor& D = descriptor_;
  const double h = bvp.h();
  for (End e : {End::Initial, End::Terminal}) {
    const bool initial = e == End::Initial;
    const BoundaryValues& b = initial ? s.start : s.end;
    const double sign = initial ? 1.0 : -1.0;  // node 1 is t = h, node N-1 is T - h
    for (int i = 0; i < r; ++i) {
      const std::string xname = boundary_name(D, initial, NodePart::Shape, i), vname = boundary_name(D, initial, NodePart::Velocity, i);
      const auto x = boundary_component(D, b, NodePart::Shape, i), v = boundary_component(D, b, NodePart::Velocity, i);
      if (x)
        bvp.fix_shape(e, 0, i, *x, xname);
      else
        bvp.natural(e, 0, i, xname + " (natural)");
      if (!v) {
        bvp.natural(e, 1, i, vname + " (natural)");
      } else if (s.closure == Closure::SecondOrder) {
        bvp.conditions.push_back({e, ConditionKind::SecondOrderVelocity, 1, i, *v, G::template identity<double>(), vname});
      } else if (x) {
        bvp.fix_shape(e, 1, i, *x + sign * h * *v, vname);
      } else {
        throw std::invalid_argument(vname + " is given without " + xname +
                                    ": the paper's first-order closure sets node 1 from both; use scheme.closure "
                                    "\"second_order\", or give " +
                                    xname);
      }
    }
    const Element target = GroupCoordinates<G>::element(group_data(b).first);
    Vec<double, d> omega = Vec<double, d>::Zero();
    for (int i = 0; i < d; ++i) omega(i) = boundary_component(D, b, NodePart::Omega, i).value_or(0.0);
    for (int i = 0; i < d; ++i) {
      const std::string gname = boundary_name(D, initial, NodePart::Group, i), wname = boundary_name(D, initial, NodePart::Omega, i);
      if (boundary_component(D, b, NodePart::Group, i))
        bvp.fix_group(e, 0, i, target, gname);
      else
        bvp.natural(e, 0, r + i, gname + " (natural)");
      if (!boundary_component(D, b, NodePart::Omega, i))
        bvp.natural(e, 1, r + i, wname + " (natural)");
      else if (s.closure == Closure::SecondOrder)
        bvp.increment_velocity(e, i, omega(i), wname);
      else
        bvp.fix_increment(e, i, G::exp(Vec<double, d>(h * omega)), wname);
    }
  }
  return bvp;
}

template <class Model, int MaxOrder, bool DerivedPaper>
ShootingGuess<typename ModelProblem<Model, MaxOrder, DerivedPaper>::PaperScheme>
ModelProblem<Model, MaxOrder, DerivedPaper>::paper_guess(const BoundaryValueProblem<PaperScheme>& bvp, const Scene& s) const {
  const BoundaryCurve c = boundary_curve(s);
  const double h = bvp.h();
  ShootingGuess<PaperScheme> guess;
  Trajectory<PaperScheme>& tr = guess.trajectory;
  tr.h = h;
  for (int n = 0; n <= bvp.N; ++n) tr.p.push_back(c.shape(n * h, false));
  const Element W = G::exp(Vec<double, d>(h * c.xi));
  for (int n = 0; n < bvp.N; ++n) tr.g.push_back(G::compose(W, connection(bvp.problem, tr.p[n], tr.p[n + 1])));
  tr.lam.assign(bvp.N - PaperScheme::order + 1, Vec<double, Model::num_constraints>::Zero());
  guess.g0 = c.g0;
  return guess;
}

template <class Model, int MaxOrder, bool DerivedPaper>
RunRecord ModelProblem<Model, MaxOrder, DerivedPaper>::solve_derived_paper(const Scene& s, const Progress& progress) const {
  using P = PaperScheme;
  const ProblemDescriptor& D = descriptor_;
  RunRecord rec = start_record("solve", s);
  describe_solver(s, rec);
  const auto make = [this](const Scene& sc) { return paper_boundary_value_problem(sc); };
  const auto first_guess = [&](const BoundaryValueProblem<P>& bvp) { return paper_guess(bvp, s); };
  const auto res = solve_scene<P>(s, make, first_guess, progress, rec);
  record_outcome(res, rec);
  const Trajectory<P>& tr = res.trajectory;
  if (tr.N() != s.N) return rec;  // no trajectory to report

  const P problem{model(s)};
  const int N = s.N;
  const double h = tr.h;
  // The cost: the windows' sum is a midpoint rule on [h/2, T − h/2] (first order in the cost);
  // half of each end window stands for the missing [0, h/2] and [T − h/2, T], which makes it a
  // trapezoidal rule to O(h²). The action (Σ L_d, what the scheme makes stationary) is kept.
  rec.cost = res.cost + 0.5 * (problem.lagrangian(tr.window_at(0), h) + problem.lagrangian(tr.window_at(N - P::order), h));
  // Node values of the scheme's order (2): velocities and Ω by central differences inside,
  // one-sided at the ends; Ω from the increments' reduced velocities ω_j (at t_{j+1/2}).
  std::vector<Vec<double, d>> w_inc;
  for (int j = 0; j < N; ++j) w_inc.push_back(reduced_velocity_of(problem, tr.p[j], tr.p[j + 1], tr.g[j], h));
  auto velocity = [&](int n) -> Vec<double, r> {
    if (n == 0) return (-3.0 * tr.p[0] + 4.0 * tr.p[1] - tr.p[2]) / (2.0 * h);
    if (n == N) return (3.0 * tr.p[N] - 4.0 * tr.p[N - 1] + tr.p[N - 2]) / (2.0 * h);
    return (tr.p[n + 1] - tr.p[n - 1]) / (2.0 * h);
  };
  auto omega = [&](int n) -> Vec<double, d> {
    if (n == 0) return 1.5 * w_inc[0] - 0.5 * w_inc[1];
    if (n == N) return 1.5 * w_inc[N - 1] - 0.5 * w_inc[N - 2];
    return 0.5 * (w_inc[n - 1] + w_inc[n]);
  };
  std::vector<double> t;
  std::vector<std::vector<double>> x(r), v(r), c(d), w(d), out(D.outputs.size(), std::vector<double>(N + 1, nan()));
  std::vector<Vec<double, d>> Pm;
  for (int n = 0; n <= N; ++n) {
    t.push_back(tr.time(n));
    const Vec<double, r> vn = velocity(n);
    const Vec<double, d> cn = GroupCoordinates<G>::coordinates(res.g[n]), wn = omega(n);
    for (int i = 0; i < r; ++i) x[i].push_back(tr.p[n](i)), v[i].push_back(vn(i));
    for (int i = 0; i < d; ++i) c[i].push_back(cn(i)), w[i].push_back(wn(i));
    if (physical_momentum) {
      Jet<Model, double> q;
      q.p = tr.p[n], q.dp = vn, q.Omega = wn;
      q.ddp.setZero(), q.dOmega.setZero();
      Pm.push_back(physical_momentum(problem.model, res.g[n], q));
    }
  }
  // Outputs on the windows' jets: window j's is at t_{j+1} (nodes 1 .. N-1; the end rows empty).
  if (outputs && !D.outputs.empty()) {
    for (int j = 0; j + P::order <= N; ++j) {
      const std::vector<double> o = outputs(problem.model, problem.jet(tr.window_at(j), h));
      for (size_t i = 0; i < D.outputs.size() && i < o.size(); ++i) out[i][j + 1] = o[i];
    }
    rec.outputs_from = "window_jets";
  }
  add_node_columns(D, t, x, c, w, v, out, rec);

  if constexpr (d > 0) {  // J_n: the scheme's discrete momentum map, conserved to roundoff
    record_momentum(problem, tr, res.g.front(), rec);
    if (physical_momentum) {
      rec.has_physical_momentum = true;
      rec.physical_momentum_drift = momentum_table<d>(Pm, N, "P", rec.momentum, rec.physical_momentum_initial);
    }
  }
  return rec;
}

}  // namespace lpshoot::app
