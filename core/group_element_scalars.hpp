// The scalars a group element is stored as, in a fixed order, for lpshoot's groups: a function
// of an element computed in a few derivative directions can then be placed into more
// (step_window_hessian.hpp embeds g~ exp(δ), computed in Hess<d>, into a window's Hess<nw>).
// A group without a specialization takes the generic route wherever this is used.
#pragma once

#include "groups.hpp"

#include <array>
#include <type_traits>

namespace lpshoot {

template <class G>
struct ElementScalars;

template <>
struct ElementScalars<SO2> {
  static constexpr int count = 1;
  template <class T>
  static std::array<T*, count> of(SO2::Element<T>& g) {
    return {&g.angle};
  }
};

template <>
struct ElementScalars<SE2> {
  static constexpr int count = 3;
  template <class T>
  static std::array<T*, count> of(SE2::Element<T>& g) {
    return {&g.angle, &g.t(0), &g.t(1)};
  }
};

template <int N>
struct ElementScalars<Rn<N>> {
  static constexpr int count = N;
  template <class T>
  static std::array<T*, count> of(typename Rn<N>::template Element<T>& g) {
    std::array<T*, count> out{};
    for (int i = 0; i < N; ++i) out[i] = &g(i);
    return out;
  }
};

template <class A, class B>
struct ElementScalars<Product<A, B>> {
  static constexpr int count = ElementScalars<A>::count + ElementScalars<B>::count;
  template <class T>
  static std::array<T*, count> of(typename Product<A, B>::template Element<T>& g) {
    const auto a = ElementScalars<A>::of(g.first);
    const auto b = ElementScalars<B>::of(g.second);
    std::array<T*, count> out{};
    for (int i = 0; i < ElementScalars<A>::count; ++i) out[i] = a[i];
    for (int i = 0; i < ElementScalars<B>::count; ++i) out[ElementScalars<A>::count + i] = b[i];
    return out;
  }
};

namespace detail {
template <class G, class = void>
struct HasElementScalars : std::false_type {};
template <class G>
struct HasElementScalars<G, std::void_t<decltype(ElementScalars<G>::count)>> : std::true_type {};
}  // namespace detail

template <class G>
constexpr bool has_element_scalars() {
  return detail::HasElementScalars<G>::value;
}

}  // namespace lpshoot
