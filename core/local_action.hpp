// The discrete constrained higher-order Lagrange–Poincaré equations without hand derivation
// (METHOD.md §2, paper eq. 50).
//
// Perturb node c by p_c -> p_c + δp, g_c -> g_c exp(η). In reduced variables only two
// increments move:
//   g~_{c-1} -> W_{c-1} exp(η) A(p_{c-1}, p_c + δp),   g~_c -> exp(-η) W_c A(p_c + δp, p_{c+1}),
// with W_i = g~_i A(p_i, p_{i+1})^{-1}. E_c is the gradient at 0 of the sum of L~ over the windows
// that contain node c. Interior nodes use all k+1 of them; boundary nodes of a boundary value
// problem use those that exist, which gives the natural boundary conditions. One forward-mode pass
// over the r + d node directions computes E_c, in any outer scalar (for its Jacobian).
#pragma once

#include "problem.hpp"

namespace lpshoot {

// Consecutive nodes 0..2k (local numbering) with their increments and the multipliers of the
// windows that start at each node. Window j covers nodes j..j+k, increments j..j+k-1, λ[j].
template <class P, class T>
struct NodeBlock {
  static constexpr int k = P::order;
  std::array<Vec<T, P::shape_dim>, 2 * k + 1> p;
  std::array<GroupElement<P, T>, 2 * k> g;
  std::array<Vec<T, P::num_constraints>, k + 1> lam;
  std::array<Vec<double, P::shape_dim>, 2 * k + 1> p_low = zero_nodes<P::shape_dim, 2 * k + 1>();  // problem.hpp's Window

  Window<P, T> window(int j) const {
    Window<P, T> a;
    for (int i = 0; i <= k; ++i) a.p[i] = p[j + i], a.p_low[i] = p_low[j + i];
    for (int i = 0; i < k; ++i) a.g[i] = g[j + i];
    return a;
  }
};

// Converts a block to a richer scalar (double -> Dual, Dual -> nested Dual), zero derivatives.
template <class TO, class P, class TI>
NodeBlock<P, TO> lift(const NodeBlock<P, TI>& b) {
  NodeBlock<P, TO> out;
  for (size_t i = 0; i < b.p.size(); ++i) out.p[i] = b.p[i].template cast<TO>();
  for (size_t i = 0; i < b.g.size(); ++i) out.g[i] = P::Group::template cast<TO>(b.g[i]);
  for (size_t i = 0; i < b.lam.size(); ++i) out.lam[i] = b.lam[i].template cast<TO>();
  out.p_low = b.p_low;
  return out;
}

// Sum of L~ over windows first..last of a block.
template <class P, class T>
T action_sum(const P& problem, const NodeBlock<P, T>& b, int first, int last, double h) {
  T S(0.0);
  for (int j = first; j <= last; ++j) S = S + augmented_lagrangian(problem, b.window(j), b.lam[j], h);
  return S;
}

// Increment g~ = W A(p0, p1) over nodes (p0, p1) when its right end (node_at_right) or its left
// end moves by (δp, η): W exp(η) A(p0, p1 + δp), or exp(-η) W A(p0 + δp, p1) (file comment).
template <class P, class T>
GroupElement<P, T> perturbed_increment(const P& problem, const GroupElement<P, T>& g, const Vec<T, P::shape_dim>& p0,
                                       const Vec<T, P::shape_dim>& p1, const Vec<T, P::shape_dim>& dp,
                                       const typename P::Group::template Tangent<T>& eta, bool node_at_right) {
  using G = typename P::Group;
  auto W = g;
  if constexpr (has_connection<P>()) W = G::compose(W, G::inverse(connection(problem, p0, p1)));
  if (node_at_right) {
    W = G::compose(W, G::template exp<T>(eta));
    if constexpr (has_connection<P>()) W = G::compose(W, connection(problem, p0, Vec<T, P::shape_dim>(p1 + dp)));
  } else {
    const typename G::template Tangent<T> minus_eta = -eta;
    W = G::compose(G::template exp<T>(minus_eta), W);
    if constexpr (has_connection<P>()) W = G::compose(W, connection(problem, Vec<T, P::shape_dim>(p0 + dp), p1));
  }
  return W;
}

// The block lifted to Dual<TO, r + d> with node c perturbed by (δp, η) in those directions
// (the increments in windows first..last move; see the file comment).
template <class P, class TO>
NodeBlock<P, Dual<TO, Dims<P>::node>> perturbed_node_block(const P& problem, const NodeBlock<P, TO>& block, int c,
                                                          int first, int last) {
  using D = Dims<P>;
  using G = typename P::Group;
  using TI = Dual<TO, D::node>;
  NodeBlock<P, TI> b = lift<TI>(block);

  Vec<TI, D::r> dp;
  for (int i = 0; i < D::r; ++i) dp(i) = TI::variable(TO(0.0), i);
  typename G::template Tangent<TI> eta;
  for (int i = 0; i < D::d; ++i) eta(i) = TI::variable(TO(0.0), D::r + i);

  if (first <= c - 1)  // g~_{c-1} is in a window
    b.g[c - 1] = perturbed_increment(problem, b.g[c - 1], b.p[c - 1], b.p[c], dp, eta, true);
  if (last >= c - D::k + 1 && c < 2 * D::k)  // g~_c is in a window
    b.g[c] = perturbed_increment(problem, b.g[c], b.p[c], b.p[c + 1], dp, eta, false);
  b.p[c] = b.p[c] + dp;
  return b;
}

// E_c (r + d entries: δp part, then η part) over windows first..last, all containing node c.
template <class P, class TO>
Vec<TO, Dims<P>::node> node_residual(const P& problem, const NodeBlock<P, TO>& block, int c,
                                     int first, int last, double h) {
  const auto S = action_sum(problem, perturbed_node_block(problem, block, c, first, last), first, last, h);
  Vec<TO, Dims<P>::node> E;
  for (int i = 0; i < Dims<P>::node; ++i) E(i) = S.d[i];
  return E;
}

// Right-trivialized derivative μ^R_{g~_i}(F) = d/dε F(exp(εζ) g~_i) of the action over windows
// first..last, as a vector in R^d (METHOD.md §2; body momentum M when the windows are all those
// containing g~_i).
template <class P>
Vec<double, P::Group::dim> right_trivialized_gradient(const P& problem, const NodeBlock<P, double>& block,
                                                      int i, int first, int last, double h) {
  using G = typename P::Group;
  constexpr int d = G::dim;
  using T = Dual<double, d>;
  NodeBlock<P, T> b = lift<T>(block);
  typename G::template Tangent<T> zeta;
  for (int a = 0; a < d; ++a) zeta(a) = T::variable(0.0, a);
  b.g[i] = G::compose(G::template exp<T>(zeta), b.g[i]);
  const T S = action_sum(problem, b, first, last, h);
  Vec<double, d> M;
  for (int a = 0; a < d; ++a) M(a) = S.d[a];
  return M;
}

}  // namespace lpshoot
