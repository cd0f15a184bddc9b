// Hager's estimate of ||A^{-1}||_1 from a factorization's solves with A and A^T (Higham,
// Algorithm 14.1, with LAPACK dlacn2's extra alternating vector, as dgecon): a lower bound, exact
// or within a small factor in practice, for a handful of solves instead of n. Used by the step
// matrices' regularity check (newton.hpp, fixed-size vectors) and by shooting's structured
// diagnostics (dynamic vectors, a sparse LU). inf or NaN when a solve meets a zero pivot.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace lpshoot {

// V: the vector type (fixed or dynamic size n); solve(b) = A^{-1} b, solve_transposed(b) = A^{-T} b.
template <class V, class Solve, class SolveTransposed>
double inverse_one_norm_estimate(const Solve& solve, const SolveTransposed& solve_transposed, int n) {
  V x = V::Constant(n, 1.0 / n);
  double estimate = 0;
  int last = -1;
  for (int iteration = 0; iteration < 5; ++iteration) {
    const V y = solve(x);
    const double e = y.template lpNorm<1>();
    if (!std::isfinite(e)) return e;
    if (iteration > 0 && e <= estimate) break;  // no progress (dlacn2's test)
    estimate = e;
    const V xi = y.unaryExpr([](double v) { return v >= 0 ? 1.0 : -1.0; });
    const V z = solve_transposed(xi);
    Eigen::Index j = 0;
    const double zmax = z.cwiseAbs().maxCoeff(&j);
    if (zmax <= z.dot(x) || j == last) break;
    x.setZero();
    x(j) = 1.0;
    last = static_cast<int>(j);
  }
  // dlacn2's safeguard against a bad start: x_i = ±(1 + i/(n-1)), |A^{-1} x|_1 · 2/(3n).
  V alt = V::Zero(n);
  for (int i = 0; i < n; ++i) alt(i) = (i % 2 == 0 ? 1.0 : -1.0) * (1.0 + (n > 1 ? double(i) / (n - 1) : 0.0));
  const double e_alt = 2.0 * solve(alt).template lpNorm<1>() / (3.0 * n);
  if (!std::isfinite(e_alt)) return e_alt;
  return std::max(estimate, e_alt);
}

}  // namespace lpshoot
