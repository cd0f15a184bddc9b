// Boundary value solves (issue 4): single vs. multiple shooting, KINSOL vs. NLopt, one vs. two
// threads, on the electron and the beanie (the data of tests/test_shooting_*.cpp), N = 100 .. 3200.
// Timed: solve_bvp only (the problem and the interpolated guess are built outside the loop),
// wall-clock (UseRealTime) so that the two-thread runs are measured as seen by the caller.
// Counters: iterations (KINSOL: Newton iterations; NLopt: constraint evaluations), residual
// (ShootingResult::residual_norm, the solver's scaled max-norm), raw_residual (the conditions in
// their own units), converged (1/0; a failed solve keeps its row, the message is the label),
// unknowns and segments.
//   ./build/bench/bench_shooting --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

#include <benchmark/benchmark.h>

#include <string>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {
constexpr double kT = 2.0;

const ElectronBoundary kElectronStart{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
const ElectronBoundary kElectronEnd{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};

BeanieControl beanie() {
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  b.variant = BeanieConstraints::ExactRotation;
  return b;
}
BeanieBoundary beanie_start() {  // well_posed_start() of tests/test_shooting_beanie.cpp
  BeanieBoundary s;
  s.psi = 0.0;
  s.psi_dot = 0.0;
  s.theta = 0.0;
  s.x = 0.0;
  s.y = 0.0;
  s.Omega1 = 0.5;
  s.Omega2 = 0.2;
  return s;
}
BeanieBoundary beanie_end() {  // well_posed_end()
  BeanieBoundary e;
  e.psi = 1.0;
  e.psi_dot = 0.0;
  e.theta = 1.0;
  return e;
}

ShootingOptions options(ShootingMethod method, int N, Backend backend, int threads) {
  ShootingOptions opt;
  opt.method = method;
  opt.segments = method == ShootingMethod::Multiple ? std::max(1, N / 50) : 1;
  opt.solver.backend = backend;
  opt.threads = threads;
  return opt;
}

template <class P>
void run(benchmark::State& state, const BoundaryValueProblem<P>& bvp, const ShootingGuess<P>& guess,
         const ShootingOptions& opt) {
  ShootingResult<P> r;
  for (auto _ : state) {
    r = solve_bvp(bvp, guess, opt);
    // Not DoNotOptimize(r.residual_norm): with libbenchmark 1.7.1 and g++ 12 its "+m,r" asm on a
    // double member corrupted the value read afterwards (google/benchmark#903, GCC PR 92597).
    benchmark::ClobberMemory();
  }
  state.counters["iterations"] = r.iterations;
  state.counters["residual"] = r.residual_norm;
  state.counters["raw_residual"] = r.raw_residual_norm;
  state.counters["converged"] = r.ok() ? 1 : 0;
  state.counters["unknowns"] = r.unknowns;
  state.counters["segments"] = opt.method == ShootingMethod::Multiple ? opt.segments : 1;
  if (!r.ok()) state.SetLabel(std::string(status_name(r.status)) + ": " + r.message);
}

void electron(benchmark::State& state, ShootingMethod method, Backend backend, int threads) {
  const int N = static_cast<int>(state.range(0));
  const auto bvp = electron_bvp(Electron{}, kT, N, kElectronStart, kElectronEnd, Closure::SecondOrder);
  run(state, bvp, electron_guess(bvp, kElectronStart, kElectronEnd), options(method, N, backend, threads));
}

void beanie(benchmark::State& state, ShootingMethod method, Backend backend, int threads) {
  const int N = static_cast<int>(state.range(0));
  const auto s = beanie_start(), e = beanie_end();
  const auto bvp = beanie_bvp(beanie(), kT, N, s, e, Closure::SecondOrder);
  run(state, bvp, beanie_guess(bvp, s, e), options(method, N, backend, threads));
}

struct Config {
  const char* name;
  void (*problem)(benchmark::State&, ShootingMethod, Backend, int);
  ShootingMethod method;
  Backend backend;
  int threads;
  int max_N;  // larger N skipped: one solve took more than ~20 s on the 2-core test machine
};

const Config kConfigs[] = {
    {"BM_Electron_Single_Kinsol", electron, ShootingMethod::Single, Backend::Kinsol, 1, 3200},
    {"BM_Electron_Multiple_Kinsol_T1", electron, ShootingMethod::Multiple, Backend::Kinsol, 1, 3200},
    {"BM_Electron_Multiple_Kinsol_T2", electron, ShootingMethod::Multiple, Backend::Kinsol, 2, 3200},
    {"BM_Electron_Multiple_Nlopt_T1", electron, ShootingMethod::Multiple, Backend::Nlopt, 1, 1600},
    {"BM_Beanie_Single_Kinsol", beanie, ShootingMethod::Single, Backend::Kinsol, 1, 3200},
    {"BM_Beanie_Multiple_Kinsol_T1", beanie, ShootingMethod::Multiple, Backend::Kinsol, 1, 1600},
    {"BM_Beanie_Multiple_Kinsol_T2", beanie, ShootingMethod::Multiple, Backend::Kinsol, 2, 1600},
    {"BM_Beanie_Multiple_Nlopt_T1", beanie, ShootingMethod::Multiple, Backend::Nlopt, 1, 800},
};
}  // namespace

// N = 100, 200, ..., max_N; three timed solves per repetition up to N = 400, one above.
int main(int argc, char** argv) {
  for (const Config& c : kConfigs)
    for (int N = 100; N <= c.max_N; N *= 2)
      benchmark::RegisterBenchmark(c.name, [c](benchmark::State& s) { c.problem(s, c.method, c.backend, c.threads); })
          ->Arg(N)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->Iterations(N <= 400 ? 3 : 1);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
