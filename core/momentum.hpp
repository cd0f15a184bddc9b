// Reconstruction and momentum (METHOD.md §3–4).
//   W_n = g~_n A(p_n, p_{n+1})^{-1},  g_{n+1} = g_n W_n;
//   M_n = μ^R_{g~_n}(sum of L~ over the windows containing g~_n)  (body momentum);
//   J_n = Ad*_{g_n^{-1}} M_n = Ad_{g_n^{-1}}^T M_n  (spatial momentum), constant along every
//   discrete solution for n = k-1 .. N-k, for any h and any multipliers.
#pragma once

#include "flow.hpp"

#include <vector>

namespace lpshoot {

template <class P>
std::vector<GroupElement<P, double>> reconstruct_group(const P& problem, const Trajectory<P>& tr,
                                                       const GroupElement<P, double>& g0) {
  using G = typename P::Group;
  std::vector<GroupElement<P, double>> g{g0};
  g.reserve(tr.g.size() + 1);
  for (size_t n = 0; n < tr.g.size(); ++n) {
    const auto A = connection(problem, tr.p[n], tr.p[n + 1]);
    g.push_back(G::compose(g.back(), G::compose(tr.g[n], G::inverse(A))));
  }
  return g;
}

// M_n for k-1 <= n <= N-k.
template <class P>
Vec<double, P::Group::dim> body_momentum(const P& problem, const Trajectory<P>& tr, int n) {
  constexpr int k = P::order;
  NodeBlock<P, double> b;
  const int o = n - k + 1;  // first window containing g~_n
  for (int i = 0; i <= 2 * k; ++i) b.p[i] = tr.p[std::min(o + i, tr.N())];
  if (tr.has_low_parts())
    for (int i = 0; i <= 2 * k; ++i) b.p_low[i] = tr.p_low[std::min(o + i, tr.N())];
  for (int i = 0; i < 2 * k; ++i) b.g[i] = tr.g[std::min<size_t>(o + i, tr.g.size() - 1)];
  for (int j = 0; j <= k; ++j) b.lam[j] = tr.lam[std::min<size_t>(o + j, tr.lam.size() - 1)];
  return right_trivialized_gradient(problem, b, k - 1, 0, k - 1, tr.h);
}

// J_n for n = k-1 .. N-k (entry i is J_{k-1+i}).
template <class P>
std::vector<Vec<double, P::Group::dim>> spatial_momentum(const P& problem, const Trajectory<P>& tr,
                                                         const GroupElement<P, double>& g0) {
  using G = typename P::Group;
  constexpr int k = P::order;
  const auto g = reconstruct_group(problem, tr, g0);
  std::vector<Vec<double, G::dim>> J;
  for (int n = k - 1; n <= tr.N() - k; ++n)
    J.push_back(G::Ad(G::inverse(g[n])).transpose() * body_momentum(problem, tr, n));
  return J;
}

// max_n |J_n - J_{k-1}| (max-norm) relative to max(1, |J_{k-1}|).
template <class P>
double momentum_drift(const P& problem, const Trajectory<P>& tr, const GroupElement<P, double>& g0) {
  const auto J = spatial_momentum(problem, tr, g0);
  if (J.empty()) return 0;
  double drift = 0;
  for (const auto& Jn : J) drift = std::max(drift, (Jn - J.front()).template lpNorm<Eigen::Infinity>());
  return drift / std::max(1.0, J.front().template lpNorm<Eigen::Infinity>());
}

}  // namespace lpshoot
