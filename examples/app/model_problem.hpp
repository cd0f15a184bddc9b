// A problem given by its continuous model (core/continuous.hpp: ℓ, constraints χ, connection)
// and a descriptor: everything the application does with it on the Galerkin schemes of order 4
// and 6, and 8 with MaxOrder = 8 (METHOD.md §9), and on the paper's nodal windows derived from the
// model (core/paper_windows.hpp, model_problem_paper.hpp) — boundary conditions from the scene, a
// guess, the solve, the columns, the momentum — with nothing written per problem. A problem with a
// hand-written discrete form (the beanie's and the electron's L_d) sets DerivedPaper = false and
// overrides solve_paper and check_paper.
//
//   const ModelProblem<MyModel> my_problem(my_descriptor(), [](const ParameterValues& v) { ... });
//   LPSHOOT_REGISTER_PROBLEM(my_problem);
//
// Each order is a compiled instance of the whole solve; order 8 (quintic, 4 Gauss points) costs
// about half as much compile time again, so it is opt-in: ModelProblem<MyModel, 8>. The scene
// reader rejects scheme.order 8 for a problem compiled without it, naming the key.
#pragma once

#include "group_coordinates.hpp"
#include "problem.hpp"
#include "run_common.hpp"

#include <functional>
#include <stdexcept>

namespace lpshoot::app {

template <class Model, int MaxOrder = 6, bool DerivedPaper = true>
class ModelProblem : public Problem {
  static_assert(MaxOrder == 6 || MaxOrder == 8, "ModelProblem: the highest Galerkin order compiled in is 6 or 8");

 public:
  using G = typename Model::Group;
  using Element = typename G::template Element<double>;
  static constexpr int r = Model::shape_dim, d = G::dim;
  template <int S>
  using Scheme = Galerkin<Model, S>;
  template <int S>
  using GuessFunction = std::function<GalerkinGuess<Scheme<S>>(const GalerkinBVP<Scheme<S>>&, const Scene&)>;
  // The paper's nodal windows of order k = 2 derived from the model, with the symmetric jet.
  using PaperScheme = PaperWindows<Model, WindowJet::Central>;

  ModelProblem(ProblemDescriptor descriptor, std::function<Model(const ParameterValues&)> make)
      : descriptor_(std::move(descriptor)), make_(std::move(make)) {
    descriptor_.galerkin_max_order = MaxOrder;
    if (DerivedPaper && descriptor_.optimal_control && descriptor_.paper_order == 0) {
      descriptor_.paper_order = PaperScheme::order;
      descriptor_.paper_derived = true;
    }
    const ProblemDescriptor& D = descriptor_;
    if (static_cast<int>(D.shape.size()) != r || static_cast<int>(D.velocity.size()) != r ||
        static_cast<int>(D.group.size()) != d || static_cast<int>(D.omega.size()) != d)
      definition_error_ = "the descriptor names " + std::to_string(D.shape.size()) + " shape, " +
                          std::to_string(D.velocity.size()) + " velocity, " + std::to_string(D.group.size()) +
                          " group and " + std::to_string(D.omega.size()) +
                          " Omega components; the model has shape_dim = " + std::to_string(r) +
                          " and a group of dimension " + std::to_string(d);
    else
      definition_error_ = descriptor_error(D, {r, r, d, d});
  }
  std::string definition_error() const override { return definition_error_; }

  // Why the boundary value problem `make()` forms is ill-posed by counting, or why it cannot be
  // formed at all (its constructor's invalid_argument), or "".
  template <class MakeBVP>
  static std::string counting_error(MakeBVP&& make) {
    try {
      return check_counting(make());
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
  }

  // Optional: derived columns at each node (descriptor().outputs names them), from the node's jet.
  std::function<std::vector<double>(const Model&, const Jet<Model, double>&)> outputs;
  // Optional: the mechanical system's own spatial momentum along the motion (columns P1..Pd), from
  // the node's group element and its data p, p', Ω (in q; q.ddp and q.dOmega are zero).
  std::function<Vec<double, d>(const Model&, const Element&, const Jet<Model, double>&)> physical_momentum;
  // Optional: problem-specific guesses; without them, default_guess.
  GuessFunction<3> guess4;
  GuessFunction<4> guess6;
  GuessFunction<5> guess8;  // used with MaxOrder = 8

  const ProblemDescriptor& descriptor() const override { return descriptor_; }
  Model model(const Scene& s) const { return make_(s.parameters); }

  RunRecord solve(const Scene& s, const Progress& progress) const override {
    if (!s.galerkin()) return solve_paper(s, progress);
    if constexpr (MaxOrder >= 8) {
      if (s.galerkin_order == 8) return solve_galerkin<5>(s, progress);
    }
    if (s.galerkin_order != 4 && s.galerkin_order != 6)  // the scene reader rejects it first
      throw SceneError(s.file + ": scheme.order: " + std::to_string(s.galerkin_order) + " is not compiled into problem \"" +
                       descriptor_.name + "\"");
    return s.galerkin_order == 6 ? solve_galerkin<4>(s, progress) : solve_galerkin<3>(s, progress);
  }

  std::string check_boundary(const Scene& s) const override {
    if (!s.galerkin()) return check_paper(s);
    return counting_error([&] { return boundary_value_problem<3>(s); });  // counting does not depend on the degree
  }

  // The scene's boundary data as conditions on the end nodes: a given component is fixed, a
  // missing one gets its natural condition (shooting/galerkin_boundary.hpp).
  template <int S>
  GalerkinBVP<Scheme<S>> boundary_value_problem(const Scene& s) const {
    using B = GalerkinBVP<Scheme<S>>;
    B bvp{model(s), s.N, s.T, {}};
    const ProblemDescriptor& D = descriptor_;
    for (End e : {End::Initial, End::Terminal}) {
      const bool initial = e == End::Initial;
      const BoundaryValues& b = initial ? s.start : s.end;
      auto impose = [&](NodePart part, int i, int component) {
        const std::string name = boundary_name(D, initial, part, i);
        if (const auto x = boundary_component(D, b, part, i))
          bvp.fix(e, component, *x, name);
        else
          bvp.natural(e, component, name + " (natural)");
      };
      for (int i = 0; i < r; ++i) impose(NodePart::Shape, i, B::x_component(i));
      for (int i = 0; i < r; ++i) impose(NodePart::Velocity, i, B::v_component(i));
      for (int i = 0; i < d; ++i) impose(NodePart::Omega, i, B::Omega_component(i));
      const Element target = GroupCoordinates<G>::element(group_data(b).first);
      for (int i = 0; i < d; ++i) {
        const std::string name = boundary_name(D, initial, NodePart::Group, i);
        if (boundary_component(D, b, NodePart::Group, i))
          bvp.fix_group(e, i, target, name);
        else
          bvp.natural(e, B::g_component(i), name + " (natural)");
      }
    }
    return bvp;
  }

  // The curve a guess follows, from the boundary data alone: each shape component by the cubic
  // Hermite interpolant of its end values and velocities (a missing value: the other end's, or
  // zero; a missing velocity: zero); the group on the one-parameter curve g_0 exp(t ξ), ξ the
  // given Ω(0) components, or those that reach g(T) when both ends give the group, or zero.
  struct BoundaryCurve {
    double T = 0;
    Vec<double, r> x0, xT, v0, vT;
    Element g0;
    Vec<double, d> xi;
    Vec<double, r> shape(double t, bool derivative) const {
      const double u = t / T;
      if (!derivative)
        return (2 * u * u * u - 3 * u * u + 1) * x0 + (u * u * u - 2 * u * u + u) * T * v0 + (-2 * u * u * u + 3 * u * u) * xT +
               (u * u * u - u * u) * T * vT;
      return ((6 * u * u - 6 * u) * x0 + (3 * u * u - 4 * u + 1) * T * v0 + (-6 * u * u + 6 * u) * xT + (3 * u * u - 2 * u) * T * vT) /
             T;
    }
  };
  BoundaryCurve boundary_curve(const Scene& s) const {
    const ProblemDescriptor& D = descriptor_;
    BoundaryCurve c;
    c.T = s.T;
    for (int i = 0; i < r; ++i) {
      const auto a = boundary_component(D, s.start, NodePart::Shape, i), b = boundary_component(D, s.end, NodePart::Shape, i);
      c.x0(i) = a ? *a : b ? *b : 0.0;
      c.xT(i) = b ? *b : c.x0(i);
      c.v0(i) = boundary_component(D, s.start, NodePart::Velocity, i).value_or(0.0);
      c.vT(i) = boundary_component(D, s.end, NodePart::Velocity, i).value_or(0.0);
    }
    const auto [c0, all0] = group_data(s.start);
    const auto [cT, allT] = group_data(s.end);
    c.g0 = GroupCoordinates<G>::element(c0);
    c.xi.setZero();
    if (all0 && allT) c.xi = G::log(G::compose(G::inverse(c.g0), GroupCoordinates<G>::element(cT))) / s.T;
    for (int i = 0; i < d; ++i)
      if (const auto w = boundary_component(D, s.start, NodePart::Omega, i)) c.xi(i) = *w;
    return c;
  }

  // A guess on the boundary curve: Ω = ξ + 𝒜(p) p'; zero bubbles and multipliers.
  template <int S>
  GalerkinGuess<Scheme<S>> default_guess(const GalerkinBVP<Scheme<S>>& bvp, const Scene& s) const {
    const double h = bvp.h();
    const BoundaryCurve c = boundary_curve(s);
    const Vec<double, d> xi = c.xi;
    auto shape = [&](double t, bool derivative) { return c.shape(t, derivative); };
    const Element g0 = c.g0;
    const Model m = bvp.model;
    auto omega = [&](double t) { return Vec<double, d>(xi + connection_velocity(m, shape(t, false), shape(t, true))); };
    GalerkinGuess<Scheme<S>> guess;
    auto& tr = guess.trajectory;
    tr.h = h;
    tr.g0 = g0;
    for (int n = 0; n < bvp.N; ++n) {
      const double t0 = n * h, t1 = (n + 1) * h;
      Interval<Scheme<S>, double> iv;
      iv.x = shape(t0, false);
      iv.v = shape(t0, true);
      iv.X2 = (shape(t1, false) - iv.x - h * iv.v) / (h * h);
      iv.V1 = (shape(t1, true) - iv.v) / h;
      iv.Om = omega(t0);
      iv.O1 = (omega(t1) - iv.Om) / h;
      iv.W = G::exp(Vec<double, d>(h * xi));
      iv.w.setZero();
      tr.intervals.push_back(iv);
    }
    return guess;
  }

 protected:
  // The paper's nodal windows: derived from the model (model_problem_paper.hpp), or the problem's
  // hand-written discrete form (an override). A free motion has no optimal control to solve.
  virtual RunRecord solve_paper(const Scene& s, const Progress& progress) const {
    if constexpr (DerivedPaper) {
      return solve_derived_paper(s, progress);
    } else {
      (void)progress;
      throw SceneError(s.file + ": scheme.discretization: problem \"" + descriptor_.name +
                       "\" has only its continuous form; use \"galerkin\"");
    }
  }
  virtual std::string check_paper(const Scene& s) const {
    if constexpr (DerivedPaper) return counting_error([&] { return paper_boundary_value_problem(s); });
    (void)s;
    return "";
  }

 public:
  // The derived paper scheme's boundary value problem: positions with their velocities through
  // the scene's closure (nodes 0, 1 and N-1, N), the group at the end nodes, Ω through the first
  // (last) increments — to second order with the second-order closure (SecondOrderIncrement),
  // g~ = exp(h Ω) with the paper's; a missing component gets its natural condition.
  BoundaryValueProblem<PaperScheme> paper_boundary_value_problem(const Scene& s) const;
  // The boundary curve on the nodes: p_n, g~_n = exp(h ξ) A(p_n, p_{n+1}), zero multipliers.
  ShootingGuess<PaperScheme> paper_guess(const BoundaryValueProblem<PaperScheme>& bvp, const Scene& s) const;

 protected:
  RunRecord solve_derived_paper(const Scene& s, const Progress& progress) const;

 private:
  // The end's group coordinates (missing ones zero) and whether all of them are given.
  std::pair<Vec<double, d>, bool> group_data(const BoundaryValues& b) const {
    Vec<double, d> c = Vec<double, d>::Zero();
    bool all = true;
    for (int i = 0; i < d; ++i) {
      const auto x = boundary_component(descriptor_, b, NodePart::Group, i);
      c(i) = x.value_or(0.0);
      all = all && x.has_value();
    }
    return {c, all};
  }

  template <int S>
  GalerkinGuess<Scheme<S>> guess(const GalerkinBVP<Scheme<S>>& bvp, const Scene& s) const {
    if constexpr (S == 3) {
      if (guess4) return guess4(bvp, s);
    } else if constexpr (S == 4) {
      if (guess6) return guess6(bvp, s);
    } else if constexpr (S == 5) {
      if (guess8) return guess8(bvp, s);
    }
    return default_guess<S>(bvp, s);
  }

  template <int S>
  RunRecord solve_galerkin(const Scene& s, const Progress& progress) const;

  ProblemDescriptor descriptor_;
  std::function<Model(const ParameterValues&)> make_;
  std::string definition_error_;
};

// A model's run at nodes 0..N (t; shape x, group coordinates c, Ω w, velocities v, outputs, each
// one vector per component): its columns in that order, the state columns (shape and group)
// and the final state.
inline void add_node_columns(const ProblemDescriptor& D, const std::vector<double>& t,
                             const std::vector<std::vector<double>>& x, const std::vector<std::vector<double>>& c,
                             const std::vector<std::vector<double>>& w, const std::vector<std::vector<double>>& v,
                             const std::vector<std::vector<double>>& out, RunRecord& rec) {
  auto add = [&](const std::vector<std::string>& names, const std::vector<std::vector<double>>& columns) {
    for (size_t i = 0; i < names.size(); ++i) rec.trajectory.add(names[i], columns[i]);
  };
  auto final_values = [&](const std::vector<std::string>& names, const std::vector<std::vector<double>>& columns) {
    for (size_t i = 0; i < names.size(); ++i) rec.final_state.emplace_back(names[i], columns[i].back());
  };
  rec.trajectory.add("t", t);
  add(D.shape, x), add(D.group, c), add(D.omega, w), add(D.velocity, v), add(D.outputs, out);
  rec.state_columns = D.shape;
  rec.state_columns.insert(rec.state_columns.end(), D.group.begin(), D.group.end());
  final_values(D.shape, x), final_values(D.velocity, v), final_values(D.group, c), final_values(D.omega, w);
}

// Columns PREFIX1.., PREFIX_drift of momenta given at nodes 0 .. J.size()-1 (empty cells after);
// returns the max drift and J_0 through `J0`.
template <int d>
double momentum_table(const std::vector<Vec<double, d>>& J, int N, const std::string& prefix, Table& table,
                      std::vector<double>& J0) {
  std::vector<std::vector<double>> comp(d, std::vector<double>(N + 1, nan()));
  std::vector<double> drift(N + 1, nan());
  double worst = 0;
  for (size_t n = 0; n < J.size(); ++n) {
    for (int a = 0; a < d; ++a) comp[a][n] = J[n](a);
    drift[n] = (J[n] - J.front()).template lpNorm<Eigen::Infinity>();
    worst = std::max(worst, drift[n]);
  }
  for (int a = 0; a < d; ++a) table.add(prefix + std::to_string(a + 1), comp[a]);
  table.add(prefix + "_drift", drift);
  J0.assign(J.front().data(), J.front().data() + d);
  return worst;
}

template <class Model, int MaxOrder, bool DerivedPaper>
template <int S>
RunRecord ModelProblem<Model, MaxOrder, DerivedPaper>::solve_galerkin(const Scene& s, const Progress& progress) const {
  using Sch = Scheme<S>;
  const ProblemDescriptor& D = descriptor_;
  RunRecord rec = start_record("solve", s);
  describe_solver(s, rec);
  const auto make = [this](const Scene& sc) { return boundary_value_problem<S>(sc); };
  const auto first_guess = [&](const GalerkinBVP<Sch>& bvp) { return guess<S>(bvp, s); };
  const auto res = solve_scene<Sch>(s, make, first_guess, progress, rec);
  record_outcome(res, rec);
  const GalerkinTrajectory<Sch>& tr = res.trajectory;
  if (tr.N() != s.N) return rec;  // no trajectory to report

  // Columns at every node 0..N: t, shape, group coordinates, Ω, velocities, outputs.
  const Model m = model(s);
  const auto g = tr.group();
  const int N = s.N;
  std::vector<double> t;
  std::vector<std::vector<double>> x(r), v(r), c(d), w(d), out(D.outputs.size());
  std::vector<Vec<double, d>> P;
  // The outputs' jets: p'' from the discrete Legendre transform where it applies, else from the
  // node velocities; Ω' from the node values (node_jets).
  std::vector<Jet<Model, double>> jets;
  NodeJetSource source = NodeJetSource::LegendreTransform;
  const bool have_jets = !D.outputs.empty() && outputs && node_jets(m, tr, jets, source);
  if (have_jets) rec.outputs_from = source == NodeJetSource::LegendreTransform ? "legendre_transform" : "node_differences";
  for (int n = 0; n <= N; ++n) {
    t.push_back(tr.time(n));
    const Vec<double, r> xn = tr.x(n), vn = tr.v(n);
    const Vec<double, d> cn = GroupCoordinates<G>::coordinates(g[n]), wn = tr.Omega(n);
    for (int i = 0; i < r; ++i) x[i].push_back(xn(i)), v[i].push_back(vn(i));
    for (int i = 0; i < d; ++i) c[i].push_back(cn(i)), w[i].push_back(wn(i));
    if (!D.outputs.empty()) {
      const std::vector<double> o = have_jets ? outputs(m, jets[n]) : std::vector<double>();
      for (size_t i = 0; i < D.outputs.size(); ++i) out[i].push_back(i < o.size() ? o[i] : nan());
    }
    if (physical_momentum) {
      Jet<Model, double> q;
      q.p = xn, q.dp = vn, q.Omega = wn;
      q.ddp.setZero(), q.dOmega.setZero();
      P.push_back(physical_momentum(m, g[n], q));
    }
  }
  add_node_columns(D, t, x, c, w, v, out, rec);

  if constexpr (d > 0) {  // J_n (n = 0..N-1): the scheme's discrete momentum map, conserved to roundoff
    const auto J = galerkin_spatial_momentum(m, tr);
    rec.momentum.add("t", t);
    rec.has_momentum = true;
    rec.momentum_drift = momentum_table<d>(J, N, "J", rec.momentum, rec.momentum_initial);
    rec.momentum_drift_relative = rec.momentum_drift / std::max(1.0, J.front().template lpNorm<Eigen::Infinity>());
    if (physical_momentum) {
      rec.has_physical_momentum = true;
      rec.physical_momentum_drift = momentum_table<d>(P, N, "P", rec.momentum, rec.physical_momentum_initial);
    }
  }
  return rec;
}

}  // namespace lpshoot::app

#include "model_problem_paper.hpp"
