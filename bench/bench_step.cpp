// One flow step: the engine's derived step (automatic differentiation of the local action,
// Newton with the exact Jacobian) against a hand-written analytic step of the same scheme
// (tests/oracles, which the tests also check against the engine).
//   ./build/bench/bench_step --benchmark_repetitions=7 --benchmark_report_aggregates_only=true
#include "beanie_cases.hpp"
#include "step_as_in_a_flow.hpp"
#include "oracles/analytic_steps.hpp"

#include <lpshoot/core/paper_windows.hpp>

#include <benchmark/benchmark.h>

using namespace lpshoot;
using problems::BeanieControl;
using problems::Electron;
using bench::beanie_state;

namespace {
FlowState<Electron> electron_state(double h) {
  FlowState<Electron> s;
  for (int i = 0; i < 4; ++i) s.p[i] = Eigen::Vector3d(1.0 + 0.1 * i * h, 0.5 * i * h, -0.2 * i * h * i * h);
  return s;
}
}  // namespace

static void BM_BeanieControlStep_Engine(benchmark::State& st) {
  const BeanieControl b = bench::beanie_control();
  const double h = 0.01;
  const auto s = beanie_state(b, h);
  const NewtonOptions opt;
  StepUnknowns<BeanieControl> z;
  for (auto _ : st) {
    const StepReport r = solve_step(b, h, s, 2, opt, z);
    benchmark::DoNotOptimize(r.iterations);
    benchmark::DoNotOptimize(z);
  }
}
BENCHMARK(BM_BeanieControlStep_Engine);

static void BM_BeanieControlStep_Analytic(benchmark::State& st) {
  const BeanieControl b = bench::beanie_control();
  const double h = 0.01;
  const auto s = beanie_state(b, h);
  for (auto _ : st) {
    auto z = oracles::beanie_control_analytic_step(b, s, h);
    benchmark::DoNotOptimize(z);
  }
}
BENCHMARK(BM_BeanieControlStep_Analytic);

static void BM_BeanieControlStep_EngineWithSensitivity(benchmark::State& st) {
  const BeanieControl b = bench::beanie_control();
  const double h = 0.01;
  const auto s = beanie_state(b, h);
  const NewtonOptions opt;
  StepUnknowns<BeanieControl> z;
  for (auto _ : st) {
    solve_step(b, h, s, 2, opt, z);
    auto dz = step_sensitivity(b, h, s, z);
    benchmark::DoNotOptimize(dz);
  }
}
BENCHMARK(BM_BeanieControlStep_EngineWithSensitivity);

// As a flow's steps run it (step_as_in_a_flow.hpp).
template <class P>
static void step_as_in_a_flow(benchmark::State& st, const P& problem, const FlowState<P>& s, double h) {
  bench::StepAsInAFlow<P> step(problem, s, h);
  int iterations = 0;
  for (auto _ : st) {
    auto dz = step(&iterations);
    benchmark::DoNotOptimize(dz);
  }
  st.counters["newton_iterations"] = iterations;
}

static void BM_BeanieControlStep_EngineWithSensitivityAsInAFlow(benchmark::State& st) {
  const BeanieControl b = bench::beanie_control();
  step_as_in_a_flow(st, b, beanie_state(b, 0.01), 0.01);
}
BENCHMARK(BM_BeanieControlStep_EngineWithSensitivityAsInAFlow);

// A flow with sensitivities (DiscreteFlow::run, all state directions seeded), per step: each
// step's Newton starts on the previous step's matrix, whose chord steps contract as the matrix
// changes from step to step (the loop above reuses the same step's: exact).
static void BM_BeanieControlFlowWithSensitivity(benchmark::State& st) {
  const BeanieControl b = bench::beanie_control();
  const double h = 0.01;
  const int N = 200;
  const DiscreteFlow<BeanieControl> flow(b, h);
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Dims<BeanieControl>::state, Dims<BeanieControl>::state);
  FlowReport report;
  for (auto _ : st) {
    auto out = flow.run(beanie_state(b, h), N, &seed);
    report = out.report;
    benchmark::DoNotOptimize(out.sensitivity);
  }
  if (!report.ok()) st.SkipWithError(report.message.c_str());
  const int steps = N - 2 * BeanieControl::order + 1;
  st.counters["per_step"] = benchmark::Counter(steps, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  st.counters["newton_per_step"] = double(report.total_iterations) / steps;
}
BENCHMARK(BM_BeanieControlFlowWithSensitivity);

// The hand-written tangent-linear step (tests/oracles/analytic_steps.cpp): value and dz/d(state).
static void BM_BeanieControlStep_AnalyticWithSensitivity(benchmark::State& st) {
  const BeanieControl b = bench::beanie_control();
  const double h = 0.01;
  const auto s = beanie_state(b, h);
  oracles::BeanieStepSensitivity dz;
  for (auto _ : st) {
    auto z = oracles::beanie_control_analytic_step(b, s, h, dz);
    benchmark::DoNotOptimize(z);
    benchmark::DoNotOptimize(dz);
  }
}
BENCHMARK(BM_BeanieControlStep_AnalyticWithSensitivity);

// The same step for the paper's windows derived from the continuous model (core/paper_windows.hpp,
// central jet; its L_d is the hand-written L^_d (79), its constraints trapezoidal on log g~).
using DerivedBeanie = PaperWindows<problems::BeanieModel>;

static FlowState<DerivedBeanie> derived_beanie_state(double h) {
  const auto s = beanie_state(bench::beanie_control(), h);
  FlowState<DerivedBeanie> d;
  d.p = s.p, d.g = s.g, d.lam = s.lam;
  return d;
}

static void BM_BeanieDerivedWindowsStep_Engine(benchmark::State& st) {
  const DerivedBeanie b{problems::BeanieModel{bench::beanie_control().par}};
  const double h = 0.01;
  const auto s = derived_beanie_state(h);
  const NewtonOptions opt;
  StepUnknowns<DerivedBeanie> z;
  for (auto _ : st) {
    const StepReport r = solve_step(b, h, s, 2, opt, z);
    benchmark::DoNotOptimize(r.iterations);
    benchmark::DoNotOptimize(z);
  }
}
BENCHMARK(BM_BeanieDerivedWindowsStep_Engine);

static void BM_BeanieDerivedWindowsStep_EngineWithSensitivity(benchmark::State& st) {
  const DerivedBeanie b{problems::BeanieModel{bench::beanie_control().par}};
  const double h = 0.01;
  const auto s = derived_beanie_state(h);
  const NewtonOptions opt;
  StepUnknowns<DerivedBeanie> z;
  for (auto _ : st) {
    solve_step(b, h, s, 2, opt, z);
    auto dz = step_sensitivity(b, h, s, z);
    benchmark::DoNotOptimize(dz);
  }
}
BENCHMARK(BM_BeanieDerivedWindowsStep_EngineWithSensitivity);

static void BM_BeanieDerivedWindowsStep_EngineWithSensitivityAsInAFlow(benchmark::State& st) {
  const DerivedBeanie b{problems::BeanieModel{bench::beanie_control().par}};
  step_as_in_a_flow(st, b, derived_beanie_state(0.01), 0.01);
}
BENCHMARK(BM_BeanieDerivedWindowsStep_EngineWithSensitivityAsInAFlow);

static void BM_ElectronStep_Engine(benchmark::State& st) {
  const Electron e;
  const double h = 0.01;
  const auto s = electron_state(h);
  const NewtonOptions opt;
  StepUnknowns<Electron> z;
  for (auto _ : st) {
    const StepReport r = solve_step(e, h, s, 2, opt, z);
    benchmark::DoNotOptimize(r.iterations);
    benchmark::DoNotOptimize(z);
  }
}
BENCHMARK(BM_ElectronStep_Engine);

static void BM_ElectronStep_Analytic(benchmark::State& st) {
  const Electron e;
  const double h = 0.01;
  const auto s = electron_state(h);
  for (auto _ : st) {
    auto x = oracles::electron_analytic_step(e, {s.p[0], s.p[1], s.p[2], s.p[3]}, h);
    benchmark::DoNotOptimize(x);
  }
}
BENCHMARK(BM_ElectronStep_Analytic);

// A nonlinear problem without a group on the paper scheme: the electron's continuous model with
// METHOD.md §9's potential 1/2 and quartic 1/8 on the derived windows (PaperWindows), flows of
// 400 steps without (Newton's matrix refreshed at every step, by nested duals in the 3
// unknowns) and with sensitivities (window a_n's Hessian each step), per step. No hand-written
// step to compare with: the isolated cost of the derived paper scheme without a group.
static void BM_NonlinearElectronPaperFlow(benchmark::State& st) {
  using P = PaperWindows<problems::ElectronModel>;
  P problem;
  problem.model.potential = 0.5, problem.model.quartic = 0.125;
  const double h = 0.01;
  const int N = 400;
  FlowState<P> s;
  const Eigen::Vector3d x0(1, 0, 0.5), v0(0, 1, -0.2), a0(0.3, -0.1, 0.2);
  for (int i = 0; i < 4; ++i) s.p[i] = x0 + i * h * v0 + 0.5 * (i * h) * (i * h) * a0;
  const Eigen::MatrixXd seed = Eigen::MatrixXd::Identity(Dims<P>::state, Dims<P>::state);
  const DiscreteFlow<P> flow(problem, h);
  FlowReport report;
  for (auto _ : st) {
    auto out = flow.run(s, N, st.range(0) ? &seed : nullptr);
    report = out.report;
    benchmark::DoNotOptimize(out.trajectory.p.back());
  }
  if (!report.ok()) st.SkipWithError(report.message.c_str());
  st.counters["per_step"] = benchmark::Counter(N, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  st.counters["newton_per_step"] = double(report.total_iterations) / N;
}
BENCHMARK(BM_NonlinearElectronPaperFlow)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
