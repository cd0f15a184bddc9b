// One Galerkin flow step (METHOD.md §9), derived by automatic differentiation: the step's Newton
// solve and its sensitivity (implicit function theorem), beanie and electron, orders 4 and 6; and
// the cost per step inside a 200-step flow with and without sensitivities (where each step's
// Newton starts from the previous step's matrix).
//   ./build/bench/bench_galerkin_step --benchmark_repetitions=7 --benchmark_report_aggregates_only=true
#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

#include "beanie_cases.hpp"
#include "electron_cases.hpp"
#include "oracles/galerkin_beanie.hpp"
#include "oracles/galerkin_electron.hpp"

#include <benchmark/benchmark.h>

using namespace lpshoot;
using namespace lpshoot::problems;
using lpshoot::bench::beanie_galerkin_start;
using lpshoot::bench::electron_start;

namespace {

constexpr double kH = 0.01;

template <class Sch>
void step(benchmark::State& st, const typename Sch::Model& model, const Interval<Sch, double>& start, bool sensitivity) {
  const NewtonOptions opt;
  Interval<Sch, double> z;
  for (auto _ : st) {
    const StepReport r = solve_galerkin_step<Sch>(model, kH, start, 1, opt, z);
    benchmark::DoNotOptimize(r.iterations);
    if (sensitivity) {
      auto dz = galerkin_step_sensitivity<Sch>(model, kH, start, z);
      benchmark::DoNotOptimize(dz);
    }
  }
}

// Per step of a 200-step flow from `start`, with the full state seeded (as shooting does) or not.
template <class Sch>
void flow(benchmark::State& st, const typename Sch::Model& model, const Interval<Sch, double>& start, bool sensitivity,
          double h = kH) {
  constexpr int steps = 200;
  const GalerkinFlow<Sch> f(model, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Sch::state, Sch::state);
  int iterations = 0;
  for (auto _ : st) {
    auto r = f.run(start, steps, sensitivity ? &seed : nullptr, Sch::Group::template identity<double>(), 0, false);
    if (!r.report.ok()) st.SkipWithError(r.report.message.c_str());
    iterations = r.report.total_iterations;
    benchmark::DoNotOptimize(r.sensitivity.data());
  }
  // Seconds per step (printed with an SI prefix: 120u = 120 µs).
  st.counters["per_step"] = benchmark::Counter(static_cast<double>(steps) * st.iterations(),
                                               benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.counters["newton_per_step"] = static_cast<double>(iterations) / steps;  // the step solves' iterations
}

BeanieModel beanie() { return bench::beanie_model(); }

}  // namespace

template <int S>
static void BM_BeanieGalerkinStep(benchmark::State& st) {
  step<BeanieGalerkin<S>>(st, beanie(), beanie_galerkin_start<S>(beanie()), st.range(0) != 0);
}
BENCHMARK_TEMPLATE(BM_BeanieGalerkinStep, 3)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_BeanieGalerkinStep, 4)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

template <int S>
static void BM_ElectronGalerkinStep(benchmark::State& st) {
  const ElectronModel m = model_of(Electron{});
  step<ElectronGalerkin<S>>(st, m, electron_start<S>(m), st.range(0) != 0);
}
BENCHMARK_TEMPLATE(BM_ElectronGalerkinStep, 3)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_ElectronGalerkinStep, 4)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// The hand-written electron Galerkin 4 step (tests/oracles/galerkin_electron.cpp: M, K and R
// formed and K factored at every call), /0 the step, /1 with its sensitivity: the baseline of
// BM_ElectronGalerkinStep<3>.
static void BM_ElectronHandGalerkinStep(benchmark::State& st) {
  const ElectronModel m = model_of(Electron{});
  const auto iv = electron_start<3>(m);
  oracles::GalerkinElectronState c;
  c << iv.x, iv.v, iv.X2, iv.V1;
  oracles::GalerkinElectronMap Phi;
  for (auto _ : st) {
    auto z = oracles::electron_galerkin4_step(m, kH, c, st.range(0) != 0 ? &Phi : nullptr);
    benchmark::DoNotOptimize(z.data());
    benchmark::DoNotOptimize(Phi.data());
  }
}
BENCHMARK(BM_ElectronHandGalerkinStep)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// A 200-step hand flow (the step map formed once, as the engine's affine flow does), /1 carrying
// the 12 x 12 sensitivity: the baseline of BM_ElectronGalerkinFlow<3>.
static void BM_ElectronHandGalerkinFlow(benchmark::State& st) {
  constexpr int steps = 200;
  const ElectronModel m = model_of(Electron{});
  const auto iv = electron_start<3>(m);
  oracles::GalerkinElectronState c0;
  c0 << iv.x, iv.v, iv.X2, iv.V1;
  const bool sensitivity = st.range(0) != 0;
  for (auto _ : st) {
    const oracles::GalerkinElectronMap Phi = oracles::electron_galerkin4_step_map(m, kH);
    oracles::GalerkinElectronState c = c0, cn;
    Eigen::Matrix<double, 12, 12> S = Eigen::Matrix<double, 12, 12>::Identity(), next;
    for (int k = 0; k < steps; ++k) {  // interval n: base node = end of interval n-1, increments Φ c
      cn.head<3>() = c.head<3>() + kH * c.segment<3>(3) + (kH * kH) * c.segment<3>(6);
      cn.segment<3>(3) = c.segment<3>(3) + kH * c.tail<3>();
      cn.tail<6>().noalias() = Phi * c;
      c.swap(cn);
      if (sensitivity) {
        next.topRows<3>() = S.topRows<3>() + kH * S.middleRows<3>(3) + (kH * kH) * S.middleRows<3>(6);
        next.middleRows<3>(3) = S.middleRows<3>(3) + kH * S.bottomRows<3>();
        next.bottomRows<6>().noalias() = Phi.lazyProduct(S);
        S.swap(next);
      }
    }
    benchmark::DoNotOptimize(c.data());
    benchmark::DoNotOptimize(S.data());
  }
  st.counters["per_step"] = benchmark::Counter(static_cast<double>(steps) * st.iterations(),
                                               benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ElectronHandGalerkinFlow)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The step's equations with the state's columns (what each sensitivity costs), electron: /0
// nested duals through the jet and ℓ (evaluate_galerkin_step_nested), /1 the chain rule through
// the jet (galerkin_flat.hpp, the engine's choice without a group; no carry: both intervals).
template <int S>
static void BM_ElectronStepDerivatives(benchmark::State& st) {
  using Sch = ElectronGalerkin<S>;
  constexpr int nz = Sch::unknowns, ns = Sch::state;
  const ElectronModel m = model_of(Electron{});
  const auto state = electron_start<S>(m);
  Interval<Sch, double> z;
  solve_galerkin_step<Sch>(m, kH, state, 1, NewtonOptions{}, z);
  Vec<double, nz> F;
  Eigen::Matrix<double, nz, nz + ns> J;
  for (auto _ : st) {
    if (st.range(0) == 0)
      evaluate_galerkin_step_nested<Sch, nz + ns>(m, kH, state, z, true, nullptr, F, J);
    else
      evaluate_galerkin_step_flat<Sch, nz + ns>(m, kH, state, z, true, nullptr, F, J);
    benchmark::DoNotOptimize(J.data());
  }
}
BENCHMARK_TEMPLATE(BM_ElectronStepDerivatives, 3)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_ElectronStepDerivatives, 4)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// One beanie interval's L~ gradient and Hessian in its coordinates (what a step with its
// sensitivity evaluates once, galerkin_group_interval.hpp): /0 the engine's, derived from
// BeanieModel's ℓ and χ, /1 written by hand (tests/oracles/galerkin_beanie.cpp).
template <int S>
static void BM_BeanieIntervalDerivatives(benchmark::State& st) {
  const BeanieModel m = beanie();
  const auto iv = beanie_galerkin_start<S>(m);
  oracles::GalerkinBeanieInterval<S> o;
  o.y << iv.x, iv.v, iv.Om, iv.X2, iv.V1, iv.O1;
  o.W_angle = iv.W.angle, o.W_t = iv.W.t;
  o.aux = iv.w;
  for (auto _ : st) {
    if (st.range(0) == 0) {
      auto d = group_interval_derivatives<BeanieGalerkin<S>>(m, iv, kH);
      benchmark::DoNotOptimize(d.hessian.data());
    } else {
      auto d = oracles::galerkin_beanie_derivatives<S>(m.par, kH, o);
      benchmark::DoNotOptimize(d.hessian.data());
    }
  }
}
BENCHMARK_TEMPLATE(BM_BeanieIntervalDerivatives, 3)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_BeanieIntervalDerivatives, 4)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// Second argument 1: h = 2e-5 (the beanie at N = 10^5), where the step equations are known only
// to their rounding (~5e-12 relative to the unknowns) and each step's Newton ends at that noise.
template <int S>
static void BM_BeanieGalerkinFlow(benchmark::State& st) {
  flow<BeanieGalerkin<S>>(st, beanie(), beanie_galerkin_start<S>(beanie()), st.range(0) != 0, st.range(1) ? 2e-5 : kH);
}
BENCHMARK_TEMPLATE(BM_BeanieGalerkinFlow, 3)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_BeanieGalerkinFlow, 4)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);

template <int S>
static void BM_ElectronGalerkinFlow(benchmark::State& st) {
  const ElectronModel m = model_of(Electron{});
  flow<ElectronGalerkin<S>>(st, m, electron_start<S>(m), st.range(0) != 0);
}
BENCHMARK_TEMPLATE(BM_ElectronGalerkinFlow, 3)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_ElectronGalerkinFlow, 4)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
