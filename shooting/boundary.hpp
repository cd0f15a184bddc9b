// Boundary value problems for the discrete flow (METHOD.md §5).
//
// Every boundary node (0 .. k-1 at the start, N-k+1 .. N at the end) has r + d components
// (shape, then group tangent). Each component gets exactly one condition: prescribed (a value,
// through a closure for velocities) or free, in which case its natural boundary condition is
// the derivative of the action sum with respect to it (the node residual over the windows that
// exist). With the k m initial constraints this makes the shooting system square by
// construction; check_counting names any component left without a condition or claimed twice.
#pragma once

#include <lpshoot/core/lpshoot.hpp>

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace lpshoot {

enum class End { Initial, Terminal };

enum class ConditionKind {
  FixedShape,           // p_n(i) = value
  FixedGroup,           // log(target^{-1} g_n)(i) = 0
  FixedIncrement,       // log(target^{-1} g~_j)(i) = 0, j = 0 or N-1; claims node 1 or N-1
  SecondOrderVelocity,  // (-3p_0 + 4p_1 - p_2)(i)/(2h) = value, or the mirror (3p_N - 4p_{N-1} + p_{N-2})
  SecondOrderIncrement, // (3 ω_0 - ω_1)(i)/2 = value, or the mirror (3 ω_{N-1} - ω_{N-2}), ω_j the reduced
                        // velocity of g~_j at t_{j+1/2} (reduced_velocity_of); claims node 1 or N-1
  Natural,              // ∂S/∂(component i of node n) = 0
};

enum class Closure {
  Paper,        // q_1 = q_0 + h q'(0), q_{N-1} = q_N - h q'(T): first order
  SecondOrder,  // one-sided second-order differences of the discrete solution
};

template <class P>
struct BoundaryCondition {
  End end = End::Initial;
  ConditionKind kind = ConditionKind::Natural;
  int offset = 0;     // node 0 + offset (initial) or N - offset (terminal)
  int component = 0;  // 0..r-1 shape, r..r+d-1 group
  double value = 0;
  GroupElement<P, double> target = P::Group::template identity<double>();
  std::string name;
};

template <class P>
struct BoundaryValueProblem {
  P problem;
  int N = 0;
  double T = 0;
  std::vector<BoundaryCondition<P>> conditions;
  double h() const { return T / N; }

  void fix_shape(End e, int offset, int i, double v, std::string name) {
    conditions.push_back({e, ConditionKind::FixedShape, offset, i, v, P::Group::template identity<double>(), name});
  }
  void fix_group(End e, int offset, int i, const GroupElement<P, double>& g, std::string name) {
    conditions.push_back({e, ConditionKind::FixedGroup, offset, P::shape_dim + i, 0.0, g, name});
  }
  void fix_increment(End e, int i, const GroupElement<P, double>& g, std::string name) {
    conditions.push_back({e, ConditionKind::FixedIncrement, 1, P::shape_dim + i, 0.0, g, name});
  }
  void natural(End e, int offset, int component, std::string name) {
    conditions.push_back(
        {e, ConditionKind::Natural, offset, component, 0.0, P::Group::template identity<double>(), name});
  }
  // Component i of the reduced group velocity Ω at an end, from the first (last) two increments
  // to second order (k = 2; the problems of core/paper_windows.hpp, whose Ω is log(g~)/h).
  void increment_velocity(End e, int i, double value, std::string name) {
    if (P::order < 2) throw std::invalid_argument("condition '" + name + "': a second-order increment velocity needs k >= 2");
    conditions.push_back({e, ConditionKind::SecondOrderIncrement, 1, P::shape_dim + i, value,
                          P::Group::template identity<double>(), name});
  }
  // Shape component i prescribed with its velocity at an end (k = 2: nodes 0, 1 or N, N-1).
  void shape_with_velocity(End e, int i, double position, double velocity, Closure c, const std::string& name) {
    fix_shape(e, 0, i, position, name);
    const double sign = e == End::Initial ? 1.0 : -1.0;
    if (c == Closure::Paper) {
      fix_shape(e, 1, i, position + sign * h() * velocity, name + "'");
    } else {
      conditions.push_back({e, ConditionKind::SecondOrderVelocity, 1, i, velocity,
                            P::Group::template identity<double>(), name + "'"});
    }
  }
};

// "" when every boundary component has exactly one condition; otherwise what is wrong.
template <class P>
std::string check_counting(const BoundaryValueProblem<P>& bvp) {
  constexpr int k = P::order, nc = P::shape_dim + P::Group::dim;
  if (bvp.N < 2 * k + 1) return "N = " + std::to_string(bvp.N) + " is too small: need N >= 2k+1 = " + std::to_string(2 * k + 1);
  if (!(bvp.T > 0)) return "T must be positive";
  std::string msg;
  for (End e : {End::Initial, End::Terminal}) {
    std::vector<int> claims(k * nc, 0);
    for (const auto& c : bvp.conditions) {
      if (c.end != e) continue;
      if (c.offset < 0 || c.offset >= k || c.component < 0 || c.component >= nc)
        return "condition '" + c.name + "' names node offset " + std::to_string(c.offset) + ", component " +
               std::to_string(c.component) + " outside the boundary (k = " + std::to_string(k) + ")";
      claims[c.offset * nc + c.component] += 1;
    }
    const char* end = e == End::Initial ? "initial" : "terminal";
    for (int o = 0; o < k; ++o)
      for (int i = 0; i < nc; ++i) {
        const int node = e == End::Initial ? o : -o;
        const std::string where = std::string(end) + " node " + (e == End::Initial ? std::to_string(node) : "N-" + std::to_string(o)) +
                                  (i < P::shape_dim ? ", shape component " + std::to_string(i)
                                                    : ", group component " + std::to_string(i - P::shape_dim));
        if (claims[o * nc + i] == 0) msg += (msg.empty() ? "" : "; ") + where + " has no condition (under-determined)";
        if (claims[o * nc + i] > 1)
          msg += (msg.empty() ? "" : "; ") + where + " has " + std::to_string(claims[o * nc + i]) +
                 " conditions (over-determined)";
      }
  }
  return msg;
}

// An extended boundary state: the flow state at one end (nodes 0..2k-1, or N-2k+1..N) and the
// absolute group element at its first node. Tangent coordinates: the state's, then g's.
template <class P>
struct BoundaryState {
  FlowState<P> s;
  GroupElement<P, double> g;
  static constexpr int size = Dims<P>::state + P::Group::dim;
};

namespace detail {
template <class P, class = void>
struct HasHalfWindow : std::false_type {};
template <class P>
struct HasHalfWindow<P, std::enable_if_t<P::has_half_window>> : std::true_type {};
}  // namespace detail

// Whether the second node of end e has a condition on component comp other than its natural one
// (a velocity through a closure, an increment, Ω).
template <class P>
bool velocity_given(const BoundaryValueProblem<P>& bvp, End e, int comp) {
  for (const auto& c : bvp.conditions)
    if (c.end == e && c.offset == 1 && c.component == comp && c.kind != ConditionKind::Natural) return true;
  return false;
}

// The natural residual of the block's node n over windows first..last (those that exist and
// contain it): the action's gradient in the node's perturbation, plus, for a problem with a half
// window (core/paper_windows.hpp), the gradient of the missing half window K at end e, taken on
// the same perturbed block. `slopes` are the end window's (end_slopes), or null without a half window.
template <class P, class T, class Slopes>
Vec<T, Dims<P>::node> natural_residual(const BoundaryValueProblem<P>& bvp, End e, const NodeBlock<P, T>& b, int n,
                                       int first, int last, const Slopes* slopes) {
  const double h = bvp.h();
  const auto moved = perturbed_node_block(bvp.problem, b, n, first, last);
  auto S = action_sum(bvp.problem, moved, first, last, h);
  if constexpr (detail::HasHalfWindow<P>::value)
    S = S + bvp.problem.half_window(moved.window(e == End::Initial ? 0 : P::order - 1), *slopes, e == End::Initial, h);
  Vec<T, Dims<P>::node> out;
  for (int i = 0; i < Dims<P>::node; ++i) out(i) = S.d[i];
  return out;
}

// Residuals of the conditions at one end, in scalar T (a Dual for Jacobians). For the initial
// end the k m initial constraints chi_d(a_0 .. a_{k-1}) come first.
template <class P, class T>
std::vector<T> boundary_residuals(const BoundaryValueProblem<P>& bvp, End e, const NodeBlock<P, T>& b,
                                  const GroupElement<P, T>& g_first) {
  using G = typename P::Group;
  constexpr int k = P::order, r = P::shape_dim;
  const double h = bvp.h();
  std::vector<T> out;
  if (e == End::Initial) {
    if constexpr (P::num_constraints > 0) {
      for (int j = 0; j < k; ++j) {
        const auto chi = bvp.problem.template constraints<T>(b.window(j), h);
        for (int i = 0; i < P::num_constraints; ++i) out.push_back(chi(i));
      }
    }
  }
  // Absolute group elements at the block's nodes: g_{c+1} = g_c g~_c A(p_c, p_{c+1})^{-1}.
  std::vector<GroupElement<P, T>> g{g_first};
  for (int c = 0; c + 1 < 2 * k; ++c)
    g.push_back(G::compose(g.back(), G::compose(b.g[c], G::inverse(connection(bvp.problem, b.p[c], b.p[c + 1])))));
  // The end window's slopes for the half window, once per end (natural_residual).
  const auto slopes = [&] {
    if constexpr (detail::HasHalfWindow<P>::value) {
      const int w = e == End::Initial ? 0 : k - 1;
      const bool natural = std::any_of(bvp.conditions.begin(), bvp.conditions.end(), [&](const auto& c) {
        return c.end == e && c.kind == ConditionKind::Natural;
      });
      return natural ? std::optional(bvp.problem.end_slopes(b.window(w), b.lam[w], h)) : std::nullopt;
    } else {
      return std::optional<int>();
    }
  }();
  for (const auto& c : bvp.conditions) {
    if (c.end != e) continue;
    const int node = e == End::Initial ? c.offset : 2 * k - 1 - c.offset;  // local index
    const int comp = c.component;
    switch (c.kind) {
      case ConditionKind::FixedShape:
        out.push_back(b.p[node](comp) - c.value);
        break;
      case ConditionKind::FixedGroup:
        out.push_back(G::log(G::compose(G::template cast<T>(G::inverse(c.target)), g[node]))(comp - r));
        break;
      case ConditionKind::FixedIncrement: {
        const int j = e == End::Initial ? 0 : 2 * k - 2;
        out.push_back(G::log(G::compose(G::template cast<T>(G::inverse(c.target)), b.g[j]))(comp - r));
        break;
      }
      case ConditionKind::SecondOrderIncrement:
        if constexpr (k >= 2) {
          const int j = e == End::Initial ? 0 : 2 * k - 2, next = e == End::Initial ? 1 : 2 * k - 3;
          const auto w = [&](int i) { return reduced_velocity_of(bvp.problem, b.p[i], b.p[i + 1], b.g[i], h)(comp - r); };
          out.push_back((3.0 * w(j) - w(next)) / 2.0 - c.value);
        }
        break;
      case ConditionKind::SecondOrderVelocity:
        if (e == End::Initial)
          out.push_back((-3.0 * b.p[0](comp) + 4.0 * b.p[1](comp) - b.p[2](comp)) / (2.0 * h) - c.value);
        else
          out.push_back((3.0 * b.p[2 * k - 1](comp) - 4.0 * b.p[2 * k - 2](comp) + b.p[2 * k - 3](comp)) / (2.0 * h) -
                        c.value);
        break;
      case ConditionKind::Natural: {
        // Windows that exist and contain the node: initial [0, node], terminal [node-k, k-1].
        const auto residual = [&](int n) {
          const int first = e == End::Initial ? 0 : n - k, last = e == End::Initial ? n : k - 1;
          return natural_residual(bvp, e, b, n, first, last, slopes ? &*slopes : nullptr)(comp);
        };
        T row = residual(node);
        // With the half window, a free end value (position, group element) whose velocity (Ω)
        // is given varies the end's first two nodes together: the row is the sum of their
        // residuals, π₁ (the momentum) at the end. Alone, node 0's residual is ℓ̃_p''/h − π₁ +
        // O(1), which holds only where ℓ̃_p'' vanishes.
        if constexpr (detail::HasHalfWindow<P>::value)
          if (c.offset == 0 && velocity_given(bvp, e, comp)) row = row + residual(e == End::Initial ? 1 : 2 * k - 2);
        out.push_back(row);
        break;
      }
    }
  }
  return out;
}

}  // namespace lpshoot
