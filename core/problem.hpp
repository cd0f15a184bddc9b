// The problem contract (METHOD.md §1).
//
// A user describes a discrete reduced problem with one struct:
//
//   struct MyProblem {
//     using Group = lpshoot::SE2;                 // the symmetry group G
//     static constexpr int shape_dim = 1;         // r, dimension of the shape space Q/G
//     static constexpr int order = 2;             // k >= 1
//     static constexpr int num_constraints = 3;   // m >= 0
//     template <class T> T lagrangian(const lpshoot::Window<MyProblem, T>& a, double h) const;
//     template <class T> lpshoot::Vec<T, 3> constraints(const lpshoot::Window<MyProblem, T>& a,
//                                                       double h) const;     // when m > 0
//     template <class T> Group::Element<T> connection(const lpshoot::Vec<T, 1>& p0,
//                                                     const lpshoot::Vec<T, 1>& p1) const;
//   };                                                                        // optional: A = e
//
// A window a_n = (p_n .. p_{n+k}, g~_n .. g~_{n+k-1}) (paper eq. 45). The functions are
// templated on the scalar so that the engine can differentiate them; they must be written
// with T arithmetic only (use value(x) for branches).
#pragma once

#include "compensated.hpp"
#include "dual.hpp"
#include "groups.hpp"

#include <Eigen/Core>

#include <array>
#include <type_traits>
#include <utility>

namespace lpshoot {

template <class T, int N>
using Vec = Eigen::Matrix<T, N, 1>;

template <class P>
struct Dims {
  using Group = typename P::Group;
  static constexpr int r = P::shape_dim;        // shape
  static constexpr int d = Group::dim;          // group
  static constexpr int m = P::num_constraints;  // constraints (multipliers per window)
  static constexpr int k = P::order;
  static constexpr int node = r + d;            // variations of one node: (δp, η)
  static constexpr int unknowns = r + d + m;    // one flow step: (p_{n+k}, ζ, λ^n)
  // Flow state before step n: p_{n-k} .. p_{n+k-1}, g~_{n-k} .. g~_{n+k-2}, λ^{n-k} .. λ^{n-1}.
  static constexpr int state = 2 * k * r + (2 * k - 1) * d + k * m;
  static_assert(k >= 1, "order k must be at least 1");
  static_assert(r >= 1, "the shape space must have dimension at least 1");
  static_assert(m >= 0, "num_constraints must be non-negative");
};

template <class P, class T>
using GroupElement = typename P::Group::template Element<T>;

template <class P, class T>
struct Window {
  std::array<Vec<T, P::shape_dim>, P::order + 1> p;
  std::array<GroupElement<P, T>, P::order> g;
  // The nodes' low parts (compensated.hpp): node i is p[i] + p_low[i]. Zero unless the problem
  // keeps them (P::keeps_low_parts); such a problem forms its differences with low_difference.
  std::array<Vec<double, P::shape_dim>, P::order + 1> p_low = zero_nodes<P::shape_dim, P::order + 1>();

  // (p[j] + p_low[j]) - (p[i] + p_low[i]) to the working precision of the difference.
  Vec<T, P::shape_dim> low_difference(int j, int i) const {
    return (p[j] - p[i]) + (p_low[j] - p_low[i]).template cast<T>();
  }
};

namespace detail {
template <class P, class T, class = void>
struct HasConnection : std::false_type {};
template <class P, class T>
struct HasConnection<P, T,
                     std::void_t<decltype(std::declval<const P&>().template connection<T>(
                         std::declval<const Vec<T, P::shape_dim>&>(),
                         std::declval<const Vec<T, P::shape_dim>&>()))>> : std::true_type {};
}  // namespace detail

// A(p0, p1): the user's discrete connection, or the identity for a trivial bundle.
template <class P, class T>
GroupElement<P, T> connection(const P& problem, const Vec<T, P::shape_dim>& p0,
                              const Vec<T, P::shape_dim>& p1) {
  if constexpr (detail::HasConnection<P, T>::value) {
    return problem.template connection<T>(p0, p1);
  } else {
    (void)problem, (void)p0, (void)p1;
    return P::Group::template identity<T>();
  }
}

template <class P>
constexpr bool has_connection() {
  return detail::HasConnection<P, double>::value;
}

namespace detail {
template <class P, class T, class = void>
struct HasReducedVelocity : std::false_type {};
template <class P, class T>
struct HasReducedVelocity<P, T,
                          std::void_t<decltype(std::declval<const P&>().template reduced_velocity<T>(
                              std::declval<const Vec<T, P::shape_dim>&>(), std::declval<const Vec<T, P::shape_dim>&>(),
                              std::declval<const GroupElement<P, T>&>(), 0.0))>> : std::true_type {};
}  // namespace detail

// The reduced group velocity that increment g~ between shapes p0 and p1 stands for: the
// problem's own reduced_velocity (paper_windows.hpp), or log(g~)/h.
template <class P, class T>
Vec<T, P::Group::dim> reduced_velocity_of(const P& problem, const Vec<T, P::shape_dim>& p0, const Vec<T, P::shape_dim>& p1,
                                          const GroupElement<P, T>& g, double h) {
  if constexpr (detail::HasReducedVelocity<P, T>::value) {
    return problem.template reduced_velocity<T>(p0, p1, g, h);
  } else {
    (void)p0, (void)p1;
    return P::Group::log(g) / h;
  }
}

// L~(a, λ) = L_d(a) + λ · chi_d(a)  (paper eq. 47).
template <class P, class T>
T augmented_lagrangian(const P& problem, const Window<P, T>& a, const Vec<T, P::num_constraints>& lam,
                       double h) {
  T L = problem.template lagrangian<T>(a, h);
  if constexpr (P::num_constraints > 0) {
    const Vec<T, P::num_constraints> chi = problem.template constraints<T>(a, h);
    for (int i = 0; i < P::num_constraints; ++i) L = L + lam(i) * chi(i);
  }
  return L;
}

}  // namespace lpshoot
