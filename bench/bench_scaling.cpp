// Solve time against N (issue 9): multiple shooting with segments "auto" (100 steps each) and
// the structured linear algebra, from N = 10^3 to 10^6, one and two threads. The electron on the
// cubic Galerkin scheme (order 4, no roundoff floor: converges at tolerance 1e-10 at every N),
// the beanie on the cubic Galerkin scheme (tolerance 1e-10; V = 1 - cos ψ, the scene's data),
// the electron (N <= 10^4) and the beanie (N <= 4000) on the paper's windows (second-order
// closure) at tolerance 1e-6: finer grids fall below the nodal scheme's roundoff floor (~u/h^3).
// The beanie at N >= 2 10^4 starts from a coarser grid's solution (the default,
// ShootingOptions::coarse_start_from); BM_BeanieGalerkin4FromGuess solves it from the guess.
// Counters: converged, iterations (on the grid itself; coarse_iterations on the coarser ones),
// unknowns, the peak resident memory of the process so far (getrusage; a high-water mark, so
// read it on the largest N of a run), and per solve the minor page faults and the kernel's CPU
// seconds (all threads): at N = 10⁶ faulting the solve's buffers in was a third of the time on some
// hosts, and does not run in parallel (bench/RESULTS.md, "N = 10⁶ on this machine"; since 2836cca
// runs with sensitivities keep no trajectory and large buffers are advised to huge pages).
//   ./build/bench/bench_scaling --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <string>

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {
constexpr double kT = 2.0;
const ElectronBoundary kStart{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
const ElectronBoundary kEnd{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};

// from_guess: without the start from coarser grids (ShootingOptions::coarse_start_from = 0),
// the comparison for the default's mesh sequencing on the beanie.
ShootingOptions options(int threads, double tolerance, bool from_guess = false) {
  ShootingOptions opt;
  if (from_guess) opt.coarse_start_from = 0;
  opt.method = ShootingMethod::Multiple;  // segments: auto
  opt.threads = threads;
  opt.solver.tolerance = tolerance;
  return opt;
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

rusage usage_now() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u;
}
double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); }

// Page faults and kernel CPU time per solve between two getrusage samples.
void report_kernel(benchmark::State& state, const rusage& before, const rusage& after) {
  const double solves = static_cast<double>(state.iterations());
  state.counters["faults"] = static_cast<double>(after.ru_minflt - before.ru_minflt) / solves;
  state.counters["sys_s"] = (seconds(after.ru_stime) - seconds(before.ru_stime)) / solves;
}

template <class R>
void report(benchmark::State& state, const R& r) {
  state.counters["converged"] = r.ok() ? 1 : 0;
  state.counters["iterations"] = r.iterations;
  state.counters["unknowns"] = r.unknowns;
  state.counters["peak_MB"] = peak_rss_mb();
  state.counters["coarse_iterations"] = r.coarse_iterations;
  if (!r.ok()) state.SetLabel(std::string(status_name(r.status)) + ": " + r.message);
}

// Times solve_bvp (problem and guess built outside the loop) and reports the last result.
template <class BVP, class Guess>
void timed_solves(benchmark::State& state, const BVP& bvp, const Guess& guess, double tolerance, bool from_guess = false) {
  decltype(solve_bvp(bvp, guess)) r;
  const rusage before = usage_now();
  for (auto _ : state) {
    r = solve_bvp(bvp, guess, options(static_cast<int>(state.range(1)), tolerance, from_guess));
    benchmark::ClobberMemory();
  }
  report_kernel(state, before, usage_now());
  report(state, r);
}

void electron_galerkin(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const auto bvp = electron_galerkin_bvp<3>(model_of(Electron{}), kT, N, kStart, kEnd);
  const auto guess = electron_galerkin_guess<3>(bvp, kStart, kEnd);
  timed_solves(state, bvp, guess, 1e-10);
}

void electron_paper(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  const auto bvp = electron_bvp(Electron{}, kT, N, kStart, kEnd, Closure::SecondOrder);
  const auto guess = electron_guess(bvp, kStart, kEnd);
  timed_solves(state, bvp, guess, 1e-6);
}

// The beanie scene's data (examples/scenes/beanie.json): ψ from rest at 0 to rest at 1, the body
// starting with Ω12 = (0.5, 0.2), θ(T) = 1.
void beanie_data(BeanieBoundary& s, BeanieBoundary& e) {
  s.psi = 0.0, s.psi_dot = 0.0, s.theta = 0.0, s.x = 0.0, s.y = 0.0, s.Omega1 = 0.5, s.Omega2 = 0.2;
  e.psi = 1.0, e.psi_dot = 0.0, e.theta = 1.0;
}

void beanie_galerkin_solve(benchmark::State& state, bool from_guess) {
  const int N = static_cast<int>(state.range(0));
  BeanieModel model;
  model.par = {1.0, 1.0, 0.5, 1.0};
  BeanieBoundary s, e;
  beanie_data(s, e);
  const auto bvp = beanie_galerkin_bvp<3>(model, kT, N, s, e);
  const auto guess = beanie_galerkin_guess<3>(bvp, s, e);
  timed_solves(state, bvp, guess, 1e-10, from_guess);
}
void beanie_galerkin(benchmark::State& state) { beanie_galerkin_solve(state, false); }
void beanie_galerkin_from_guess(benchmark::State& state) { beanie_galerkin_solve(state, true); }

void beanie_paper(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0));
  BeanieControl b;
  b.par = {1.0, 1.0, 0.5, 1.0};
  b.variant = BeanieConstraints::ExactRotation;
  BeanieBoundary s, e;
  beanie_data(s, e);
  const auto bvp = beanie_bvp(b, kT, N, s, e, Closure::SecondOrder);
  const auto guess = beanie_guess(bvp, s, e);
  timed_solves(state, bvp, guess, 1e-6);
}
}  // namespace

int main(int argc, char** argv) {
  for (int threads : {1, 2}) {
    for (int N : {1000, 10000, 100000, 1000000})
      benchmark::RegisterBenchmark("BM_ElectronGalerkin4", electron_galerkin)->Args({N, threads})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
    for (int N : {1000, 10000, 100000, 1000000})
      benchmark::RegisterBenchmark("BM_BeanieGalerkin4", beanie_galerkin)->Args({N, threads})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
    if (threads == 1)
      for (int N : {100000, 1000000})
        benchmark::RegisterBenchmark("BM_BeanieGalerkin4FromGuess", beanie_galerkin_from_guess)->Args({N, threads})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
    for (int N : {1000, 3000, 10000})
      benchmark::RegisterBenchmark("BM_ElectronPaper", electron_paper)->Args({N, threads})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
    for (int N : {1000, 2000, 4000})
      benchmark::RegisterBenchmark("BM_BeaniePaper", beanie_paper)->Args({N, threads})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
