// Nodes kept to twice the working precision (issue 13; METHOD.md §9, "store increments"): a node
// is the unevaluated sum hi + lo of two doubles (Dekker's double-double), so that the differences
// of neighbouring nodes, Δp and Δ²p, are formed to the working precision of the difference
// itself rather than of the node. A flow on nodes rounded to doubles perturbs every new node by
// ~u |p|, and the step's recursion (a difference equation of order 2k) amplifies these like
// u |p| N^{2k - 1/2}; on hi + lo nodes what is left is the rounding of the differences, as in
// Henrici's summed form, which stores the differences themselves. Problems opt in with
// `static constexpr bool keeps_low_parts = true` and form their differences with low_difference
// (paper_windows.hpp); other problems see lo = 0 and keep today's nodal arithmetic.
#pragma once

#include <Eigen/Core>

#include <array>
#include <type_traits>

namespace lpshoot {

namespace detail {
template <class P, class = void>
struct KeepsLowParts : std::false_type {};
template <class P>
struct KeepsLowParts<P, std::enable_if_t<P::keeps_low_parts>> : std::true_type {};
}  // namespace detail

// True when the flow keeps the low parts of P's nodes (P::keeps_low_parts).
template <class P>
constexpr bool keeps_low_parts() {
  return detail::KeepsLowParts<P>::value;
}

template <int r, std::size_t n>
std::array<Eigen::Matrix<double, r, 1>, n> zero_nodes() {
  std::array<Eigen::Matrix<double, r, 1>, n> a;
  for (auto& v : a) v.setZero();
  return a;
}

// s + e = a + b exactly (Knuth's TwoSum; no ordering of |a|, |b| needed).
inline void two_sum(double a, double b, double& s, double& e) {
  s = a + b;
  const double bb = s - a;
  e = (a - (s - bb)) + (b - bb);
}

// (hi, lo) <- hi + lo + x, renormalized (|lo| <= half an ulp of hi).
template <class V>
void add_compensated(V& hi, V& lo, const V& x) {
  for (Eigen::Index i = 0; i < hi.size(); ++i) {
    double s, e;
    two_sum(hi(i), x(i), s, e);
    two_sum(s, lo(i) + e, hi(i), lo(i));
  }
}

// (hi, lo) <- (a_hi + a_lo) - (b_hi + b_lo) to double-double precision: the new node of a
// linear extrapolation, 2 p_{n+k-1} - p_{n+k-2}, is formed with a = 2 p_{n+k-1} (exact).
template <class V>
void subtract_compensated(const V& a_hi, const V& a_lo, const V& b_hi, const V& b_lo, V& hi, V& lo) {
  for (Eigen::Index i = 0; i < a_hi.size(); ++i) {
    double s, e;
    two_sum(a_hi(i), -b_hi(i), s, e);
    two_sum(s, e + (a_lo(i) - b_lo(i)), hi(i), lo(i));
  }
}

}  // namespace lpshoot
