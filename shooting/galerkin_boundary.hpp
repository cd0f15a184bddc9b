// Boundary value problems for the Galerkin schemes (METHOD.md §9): conditions on the end nodes'
// data, imposed exactly (no closure).
//
// Each end node has 2r + 2d components, in the node layout (x: 0..r-1, v: r..2r-1, Ω: 2r..2r+d-1,
// g: 2r+d..2r+2d-1; g through log(target^{-1} g)). Each component gets exactly one condition:
// fixed, or free with its natural boundary condition (the derivative of the action with respect
// to it, node_residual of the one adjacent interval). The first interval's own equations (bubbles,
// constraints at its Gauss points) join the initial rows; the flow solves every later interval's.
// That makes the shooting system square by construction; check_counting names any component
// left without a condition or claimed twice.
#pragma once

#include "boundary.hpp"

#include <lpshoot/core/galerkin_end_rows.hpp>
#include <lpshoot/core/galerkin_flow.hpp>

namespace lpshoot {

template <class Sch>
struct GalerkinCondition {
  End end = End::Initial;
  ConditionKind kind = ConditionKind::Natural;  // FixedShape (any of x, v, Ω), FixedGroup or Natural
  int component = 0;                            // node layout, 0 .. 2r + 2d - 1
  double value = 0;
  typename Sch::Group::template Element<double> target = Sch::Group::template identity<double>();
  std::string name;
};

template <class Sch>
struct GalerkinBVP {
  using Model = typename Sch::Model;
  using G = typename Sch::Group;
  static constexpr int components = 2 * Sch::r + 2 * Sch::d;
  static constexpr int x_component(int i) { return i; }
  static constexpr int v_component(int i) { return Sch::r + i; }
  static constexpr int Omega_component(int i) { return 2 * Sch::r + i; }
  static constexpr int g_component(int i) { return 2 * Sch::r + Sch::d + i; }

  Model model;
  int N = 0;
  double T = 0;
  std::vector<GalerkinCondition<Sch>> conditions;
  double h() const { return T / N; }

  void fix(End e, int component, double value, std::string name) {
    conditions.push_back({e, ConditionKind::FixedShape, component, value, G::template identity<double>(), std::move(name)});
  }
  void fix_group(End e, int i, const typename G::template Element<double>& target, std::string name) {
    conditions.push_back({e, ConditionKind::FixedGroup, g_component(i), 0.0, target, std::move(name)});
  }
  void natural(End e, int component, std::string name) {
    conditions.push_back({e, ConditionKind::Natural, component, 0.0, G::template identity<double>(), std::move(name)});
  }
};

template <class Sch>
std::string check_counting(const GalerkinBVP<Sch>& bvp) {
  constexpr int nc = GalerkinBVP<Sch>::components, r = Sch::r, d = Sch::d;
  if (bvp.N < 2) return "N = " + std::to_string(bvp.N) + " is too small: a Galerkin scheme needs N >= 2";
  if (!(bvp.T > 0)) return "T must be positive";
  std::string msg;
  auto component_name = [&](int i) {
    if (i < r) return "position component " + std::to_string(i);
    if (i < 2 * r) return "velocity component " + std::to_string(i - r);
    if (i < 2 * r + d) return "group velocity component " + std::to_string(i - 2 * r);
    return "group component " + std::to_string(i - 2 * r - d);
  };
  for (End e : {End::Initial, End::Terminal}) {
    std::vector<int> claims(nc, 0);
    for (const auto& c : bvp.conditions) {
      if (c.end != e) continue;
      if (c.component < 0 || c.component >= nc)
        return "condition '" + c.name + "' names component " + std::to_string(c.component) + " of " + std::to_string(nc);
      if (c.kind == ConditionKind::FixedGroup && c.component < 2 * r + d)
        return "condition '" + c.name + "' fixes a group element on a non-group component";
      if (c.kind == ConditionKind::FixedShape && c.component >= 2 * r + d)
        return "condition '" + c.name + "' fixes a group component by value (use fix_group)";
      claims[c.component] += 1;
    }
    const std::string end = e == End::Initial ? "initial node" : "terminal node";
    for (int i = 0; i < nc; ++i) {
      if (claims[i] == 0) msg += (msg.empty() ? "" : "; ") + end + ", " + component_name(i) + " has no condition (under-determined)";
      if (claims[i] > 1)
        msg += (msg.empty() ? "" : "; ") + end + ", " + component_name(i) + " has " + std::to_string(claims[i]) +
               " conditions (over-determined)";
    }
  }
  return msg;
}

// Residuals of one end's conditions in scalar T, from the end interval (the first, or the last)
// and g at its base node. The initial end starts with the first interval's own equations.
// `action_rows`, if given, holds the rows that come from the action, (E, own rows) at the
// initial end and E at the terminal one (galerkin_end_rows, with their derivatives in T);
// otherwise they are computed here.
template <class Sch, class T>
std::vector<T> galerkin_boundary_residuals(const GalerkinBVP<Sch>& bvp, End e, const Interval<Sch, T>& iv,
                                           const typename Sch::Group::template Element<T>& g_base,
                                           const Vec<T, Sch::unknowns>* action_rows = nullptr) {
  using G = typename Sch::Group;
  constexpr int r = Sch::r, d = Sch::d;
  const double h = bvp.h();
  std::vector<T> out;
  const bool initial = e == End::Initial;
  if (initial) {
    const Vec<T, Sch::aux> a = action_rows ? Vec<T, Sch::aux>(action_rows->template segment<Sch::aux>(Sch::variation))
                                           : aux_residual<Sch, T>(bvp.model, iv, h);
    for (int i = 0; i < Sch::aux; ++i) out.push_back(a(i));
  }
  Vec<T, 2 * r + d> node;
  node << (initial ? iv.x : iv.x_end(h)), (initial ? iv.v : iv.v_end(h)), (initial ? iv.Om : iv.Om_end(h));
  const auto g = initial ? g_base : G::compose(g_base, iv.W);
  Vec<T, Sch::variation> natural;
  bool have_natural = false;
  for (const auto& c : bvp.conditions) {
    if (c.end != e) continue;
    switch (c.kind) {
      case ConditionKind::FixedShape:
        out.push_back(node(c.component) - c.value);
        break;
      case ConditionKind::FixedGroup:
        out.push_back(G::log(G::compose(G::template cast<T>(G::inverse(c.target)), g))(c.component - 2 * r - d));
        break;
      case ConditionKind::Natural:
        if (!have_natural && action_rows) {
          natural = action_rows->template head<Sch::variation>();
          have_natural = true;
        } else if (!have_natural) {
          natural = initial ? node_residual<Sch, T>(bvp.model, nullptr, &iv, h) : node_residual<Sch, T>(bvp.model, &iv, nullptr, h);
          have_natural = true;
        }
        out.push_back(natural(c.component));
        break;
      default:
        throw std::invalid_argument("condition '" + c.name + "': not a Galerkin boundary condition");
    }
  }
  return out;
}

// Names of the first interval's own equations, in galerkin_boundary_residuals' order.
template <class Sch>
std::vector<std::string> galerkin_initial_equation_names() {
  std::vector<std::string> names;
  for (int j = 0; j < Sch::bubbles; ++j)
    for (int a = 0; a < Sch::r + Sch::d; ++a)
      names.push_back("first interval: bubble " + std::to_string(j) + (a < Sch::r ? " of shape component " + std::to_string(a)
                                                                                   : " of group component " + std::to_string(a - Sch::r)));
  for (int i = 0; i < Sch::gauss; ++i)
    for (int c = 0; c < Sch::m; ++c)
      names.push_back("first interval: constraint " + std::to_string(c) + " at Gauss point " + std::to_string(i));
  return names;
}

}  // namespace lpshoot
