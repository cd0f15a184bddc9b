// The floor of a linear solve (issue 9): the electron's Galerkin 4 transfer (linear: ℓ is a
// quadratic form in the jet) solved by one banded direct solve, LAPACK's dgbsv, against
// lpshoot's multiple-shooting solve of the same discrete equations, in the same run.
//
// L~ of an interval is a quadratic form in its coordinates θ = (x, v, X2, V1) (galerkin.hpp),
// with a Hessian K taken from the engine once (nested duals on interval_action). Two banded
// forms of the discrete Euler–Lagrange system, with the boundary data at both ends:
// - form 0, node unknowns u_n = (x_n, v_n): node n's equation couples nodes n-1, n, n+1 (the
//   smallest band, kl = ku = 11), but node differences lose ~ε/h⁴ (METHOD.md §9);
// - form 1, lpshoot's own variables: θ_n for every interval, node n's equation E_n in the
//   engine's scaled directions, and continuity u_{n+1} = (x_n + h v_n + h² X2_n, v_n + h V1_n)
//   (multiple shooting with one-step segments; kl = 17, ku = 11).
// Neither has lpshoot's continuity structure per segment, diagnostics or convergence checks.
//
// BM_BandedFloor/N/form: one dgbsv (factor and solve; the matrix is copied outside the timing).
// Counter max_diff: max over nodes of |x_n - x_n(lpshoot)|.
// BM_ElectronGalerkin4Solve/N: solve_bvp, multiple shooting, segments "auto", one thread,
// tolerance 1e-10, problem and guess built outside the timing (as bench_scaling).
//   ./build/bench/bench_floor --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <lpshoot/problems/electron_bvp.hpp>

#include <benchmark/benchmark.h>

#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

extern "C" void dgbsv_(const int* n, const int* kl, const int* ku, const int* nrhs, double* ab, const int* ldab,
                       int* ipiv, double* b, const int* ldb, int* info);

using namespace lpshoot;
using namespace lpshoot::problems;

namespace {
using Sch = ElectronGalerkin<3>;
constexpr double kT = 2.0;
const ElectronBoundary kStart{Eigen::Vector3d(1.0, 0.0, 0.5), Eigen::Vector3d(0.0, 1.0, 0.0)};
const ElectronBoundary kEnd{Eigen::Vector3d(0.0, 1.0, -0.5), Eigen::Vector3d(-1.0, 0.0, 0.2)};

// K = ∂²L~/∂θ² of one interval in its own coordinates θ = (x, v, X2, V1); exact (L~ is
// quadratic, and homogeneous: no linear term).
Eigen::Matrix<double, 12, 12> interval_hessian(const ElectronModel& model, double h) {
  using Inner = Dual<double, 12>;
  using Outer = Dual<Inner, 12>;
  Vec<Outer, 12> y;
  for (int i = 0; i < 12; ++i) y(i) = Outer::variable(Inner::variable(0.0, i), i);
  Interval<Sch, Outer> iv;
  iv.x = y.segment<3>(0), iv.v = y.segment<3>(3), iv.X2 = y.segment<3>(6), iv.V1 = y.segment<3>(9);
  const Outer L = interval_action(model, iv, h);
  Eigen::Matrix<double, 12, 12> K;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) K(i, j) = L.d[i].d[j];
  return K;
}

// The system in LAPACK band storage (ldab = 2 kl + ku + 1) and its right-hand side.
struct BandedSystem {
  int n = 0, kl = 0, ku = 0, ldab = 0;
  std::vector<double> ab, rhs;
  BandedSystem(int size, int lower, int upper) : n(size), kl(lower), ku(upper), ldab(2 * lower + upper + 1) {
    ab.assign(static_cast<size_t>(ldab) * n, 0.0);
    rhs.assign(n, 0.0);
  }
  void add(int i, int j, double a) {
    if (i - j > kl || j - i > ku) throw std::logic_error("entry outside the band");
    ab[(kl + ku + i - j) + static_cast<size_t>(j) * ldab] += a;
  }
};

using Node = Eigen::Matrix<double, 6, 1>;
const Node kU0 = (Node() << kStart.position, kStart.velocity).finished();
const Node kUN = (Node() << kEnd.position, kEnd.velocity).finished();

// Node form: unknowns u_n = (x_n, v_n), n = 0..N; row block n is node n's equation
// ∂(L~_{n-1} + L~_n)/∂u_n = 0 (interior) or u_n given (ends). With θ = M (u_n, u_{n+1}), the
// interval's Hessian in (u_n, u_{n+1}) is Mᵀ K M. Smallest band (kl = ku = 11), but node
// differences lose ~ε/h⁴ (METHOD.md §9).
BandedSystem assemble_nodes(int N) {
  const double h = kT / N;
  Eigen::Matrix<double, 12, 12> M = Eigen::Matrix<double, 12, 12>::Zero();
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  M.block<6, 6>(0, 0).setIdentity();
  M.block<3, 3>(6, 0) = -I / (h * h), M.block<3, 3>(6, 3) = -I / h, M.block<3, 3>(6, 6) = I / (h * h);
  M.block<3, 3>(9, 3) = -I / h, M.block<3, 3>(9, 9) = I / h;
  const Eigen::Matrix<double, 12, 12> H = M.transpose() * interval_hessian(model_of(Electron{}), h) * M;
  BandedSystem s(6 * (N + 1), 11, 11);
  for (int n = 0; n < N; ++n)
    for (int a = 0; a < 12; ++a) {
      const int node = n + a / 6;
      if (node == 0 || node == N) continue;
      for (int b = 0; b < 12; ++b) s.add(6 * n + a, 6 * n + b, H(a, b));
    }
  for (int c = 0; c < 6; ++c) {
    s.add(c, c, 1.0), s.rhs[c] = kU0(c);
    s.add(6 * N + c, 6 * N + c, 1.0), s.rhs[6 * N + c] = kUN(c);
  }
  return s;
}

// Increment form, lpshoot's own variables: unknowns θ_n = (x_n, v_n, X2_n, V1_n), n < N, then
// u_N. Rows of interval n: node n's equation E_n (the engine's scaled directions, galerkin.hpp
// perturb_node: interval n-1's X2, V1 += e; interval n's x += h² e_x, v += h e_v,
// X2 -= e_x + e_v, V1 -= e_v; divided by h), or u_0 given for n = 0; then continuity
// u_{n+1} = (x_n + h v_n + h² X2_n, v_n + h V1_n). Band kl = 17, ku = 11.
BandedSystem assemble_increments(int N) {
  const double h = kT / N;
  const Eigen::Matrix<double, 12, 12> K = interval_hessian(model_of(Electron{}), h);
  Eigen::Matrix<double, 12, 6> Pl = Eigen::Matrix<double, 12, 6>::Zero(), Pr = Pl;  // dθ/de
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Pl.block<6, 6>(6, 0).setIdentity();
  Pr.block<3, 3>(0, 0) = h * h * I, Pr.block<3, 3>(3, 3) = h * I;
  Pr.block<3, 3>(6, 0) = -I, Pr.block<3, 3>(6, 3) = -I, Pr.block<3, 3>(9, 3) = -I;
  const Eigen::Matrix<double, 6, 12> El = Pl.transpose() * K / h, Er = Pr.transpose() * K / h;
  BandedSystem s(12 * N + 6, 17, 11);
  for (int n = 0; n < N; ++n) {
    const int row = 12 * n, col = 12 * n;
    for (int a = 0; a < 6; ++a) {
      if (n == 0) {
        s.add(a, a, 1.0), s.rhs[a] = kU0(a);
        continue;
      }
      for (int b = 0; b < 12; ++b) s.add(row + a, col - 12 + b, El(a, b)), s.add(row + a, col + b, Er(a, b));
    }
    for (int a = 0; a < 6; ++a) {  // continuity: u_{n+1} - (u_n + h (v_n, 0) + (h² X2_n, h V1_n)) = 0
      s.add(row + 6 + a, col + 12 + a, 1.0);
      s.add(row + 6 + a, col + a, -1.0);
      if (a < 3) s.add(row + 6 + a, col + 3 + a, -h);
      s.add(row + 6 + a, col + 6 + a, a < 3 ? -h * h : -h);
    }
  }
  for (int c = 0; c < 6; ++c) s.add(12 * N + c, 12 * N + c, 1.0), s.rhs[12 * N + c] = kUN(c);
  return s;
}

// Factors and solves in place: ab is overwritten by the LU factors, rhs by the solution.
void banded_solve(BandedSystem& s, std::vector<int>& ipiv) {
  const int nrhs = 1;
  int info = 0;
  dgbsv_(&s.n, &s.kl, &s.ku, &nrhs, s.ab.data(), &s.ldab, ipiv.data(), s.rhs.data(), &s.n, &info);
  if (info != 0) throw std::runtime_error("dgbsv failed, info = " + std::to_string(info));
}

enum Form { Nodes = 0, Increments = 1 };

BandedSystem assemble(int N, int form) { return form == Nodes ? assemble_nodes(N) : assemble_increments(N); }

// x_n from a banded solution.
Eigen::Vector3d banded_position(const BandedSystem& s, int form, int n) {
  const int i = form == Nodes ? 6 * n : 12 * n;
  return Eigen::Vector3d(s.rhs[i], s.rhs[i + 1], s.rhs[i + 2]);
}

// The problem and its guess (cubic Hermite interpolation of the boundary data), built outside
// the timing as in bench_scaling.
struct ElectronCase {
  GalerkinBVP<Sch> bvp;
  GalerkinGuess<Sch> guess;
  explicit ElectronCase(int N)
      : bvp(electron_galerkin_bvp<3>(model_of(Electron{}), kT, N, kStart, kEnd)),
        guess(electron_galerkin_guess<3>(bvp, kStart, kEnd)) {}
};

ShootingResult<Sch> lpshoot_solve(const ElectronCase& c) {
  ShootingOptions opt;
  opt.method = ShootingMethod::Multiple;  // segments: auto
  opt.threads = 1;
  opt.solver.tolerance = 1e-10;
  return solve_bvp(c.bvp, c.guess, opt);
}

// The node positions of lpshoot's solution, computed once per N.
const std::vector<Eigen::Vector3d>& lpshoot_positions(int N) {
  static std::map<int, std::vector<Eigen::Vector3d>> cache;
  if (auto it = cache.find(N); it != cache.end()) return it->second;
  const auto r = lpshoot_solve(ElectronCase(N));
  if (!r.ok()) throw std::runtime_error("lpshoot did not converge at N = " + std::to_string(N) + ": " + r.message);
  std::vector<Eigen::Vector3d> x;
  for (const auto& iv : r.trajectory.intervals) x.push_back(iv.x);
  x.push_back(r.trajectory.intervals.back().x_end(kT / N));
  return cache[N] = std::move(x);
}

// BM_BandedFloor/N/form: one dgbsv. Counter max_diff: max_n |x_n - x_n(lpshoot)|.
void banded_floor(benchmark::State& state) {
  const int N = static_cast<int>(state.range(0)), form = static_cast<int>(state.range(1));
  const BandedSystem assembled = assemble(N, form);
  BandedSystem s = assembled;
  std::vector<int> ipiv(s.n);
  for (auto _ : state) {
    state.PauseTiming();
    std::memcpy(s.ab.data(), assembled.ab.data(), assembled.ab.size() * sizeof(double));
    std::memcpy(s.rhs.data(), assembled.rhs.data(), assembled.rhs.size() * sizeof(double));
    state.ResumeTiming();
    banded_solve(s, ipiv);
    benchmark::ClobberMemory();
  }
  const auto& x = lpshoot_positions(N);
  double diff = 0;
  for (int n = 0; n <= N; ++n) diff = std::max(diff, (banded_position(s, form, n) - x[n]).cwiseAbs().maxCoeff());
  state.counters["unknowns"] = s.n;
  state.counters["max_diff"] = diff;
  state.SetLabel(form == Nodes ? "node form" : "increment form");
}

void lpshoot_galerkin4(benchmark::State& state) {
  const ElectronCase c(static_cast<int>(state.range(0)));
  ShootingResult<Sch> r;
  for (auto _ : state) {
    r = lpshoot_solve(c);
    benchmark::ClobberMemory();
  }
  state.counters["converged"] = r.ok() ? 1 : 0;
  state.counters["unknowns"] = r.unknowns;
}
}  // namespace

int main(int argc, char** argv) {
  for (int N : {1000, 10000, 100000, 1000000}) {
    for (int form : {Nodes, Increments})
      benchmark::RegisterBenchmark("BM_BandedFloor", banded_floor)->Args({N, form})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(N < 100000 ? 20 : 1);
    benchmark::RegisterBenchmark("BM_ElectronGalerkin4Solve", lpshoot_galerkin4)->Arg(N)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(N < 100000 ? 5 : 1);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
