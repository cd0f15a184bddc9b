// Galerkin solves on fine grids start from a coarser grid's solution (mesh sequencing): the
// problem is solved first on N / coarse_ratio steps, from the guess carried to that grid, and
// that solution, carried back (galerkin_resample.hpp: each fine interval is the coarse curve
// restricted to it), is the fine solve's guess. The coarse grid does the same while its N is
// large enough (N = 10^6 starts from 10^4, which is solved from the guess).
//
// Why it pays: Newton on the fine grid then starts near its solution and needs about one
// iteration where the guess needs four or five, and each coarse solve costs a 1/coarse_ratio
// share of a fine one. The beanie on Galerkin 4 at N = 10^5, tolerance 1e-10: from the
// interpolated guess 5 iterations (7e8 -> 0.8 x tolerance), from N = 10^3 one (5.7e6 -> 0.24);
// from N = 10^4 also one (5.2e5 -> 0.29). The carried start's residual shrinks only like H (the
// carried multipliers and increments satisfy the fine equations to low order), which keeps it
// well above a fine grid's roundoff floor: a start within 1000x the floor would not be
// recognized as stalled at the noise (kinsol_backend.cpp) and would go on to a line search.
// Problems whose steps are affine (degree.hpp) converge in one iteration from any guess and are
// solved directly.
//
// When the coarse grid does not converge, or its solution does not lead the fine solve to
// convergence (the fine grid resolves what the coarse one cannot, e.g. a stiff potential), the
// fine grid is solved from the guess as without it; the result's detail names what happened.
// A fine solve that stalls at its roundoff floor, or finds its Jacobian rank deficient, stands:
// neither depends on where Newton started.
#pragma once

#include "galerkin_resample.hpp"
#include "shooting.hpp"

#include <chrono>
#include <string>

namespace lpshoot {
namespace detail {

// The grid a Galerkin solve on N steps first solves on (ShootingOptions::coarse_start_from and
// coarse_ratio), or 0 for none.
inline int coarse_grid(int N, bool affine, const ShootingOptions& opt) {
  if (affine || opt.coarse_start_from <= 0 || N < opt.coarse_start_from || opt.coarse_ratio < 2) return 0;
  const int Nc = N / opt.coarse_ratio;
  return Nc >= 2 ? Nc : 0;  // a Galerkin scheme needs N >= 2
}

}  // namespace detail

template <class Sch>
ShootingResult<Sch> solve_bvp(const GalerkinBVP<Sch>& bvp, const GalerkinGuess<Sch>& guess, const ShootingOptions& opt = {}) {
  using A = SchemeFor<Sch>;
  const int Nc = A::check(bvp, guess).empty() ? detail::coarse_grid(bvp.N, A::affine(bvp, opt.step), opt) : 0;
  if (Nc == 0) return solve_bvp_with<Sch>(bvp, guess, opt);
  const auto t0 = std::chrono::steady_clock::now();
  auto finish = [&](ShootingResult<Sch> r) {
    r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  };
  ShootingOptions direct = opt;
  direct.coarse_start_from = 0;

  GalerkinBVP<Sch> coarse_bvp = bvp;
  coarse_bvp.N = Nc;
  // The same options (the progress callbacks report and may interrupt the coarse solve too).
  const ShootingResult<Sch> coarse =
      solve_bvp(coarse_bvp, GalerkinGuess<Sch>{resample_trajectory(bvp.model, guess.trajectory, Nc)}, opt);
  const int coarse_iterations = coarse.iterations + coarse.coarse_iterations;
  std::string tried;
  int fine_iterations = 0;  // of a start from the coarse solution that did not converge
  if (coarse.ok()) {
    ShootingResult<Sch> out =
        solve_bvp_with<Sch>(bvp, GalerkinGuess<Sch>{resample_trajectory(bvp.model, coarse.trajectory, bvp.N)}, direct);
    if (out.ok() || out.stalled_at_floor || out.status == ShootingStatus::RankDeficient) {
      out.coarse_grids = coarse.coarse_grids;
      out.coarse_grids.push_back(Nc);
      out.coarse_iterations = coarse_iterations;
      return finish(std::move(out));
    }
    tried = "from the solution on N = " + std::to_string(Nc) + ": " + out.message;
    fine_iterations = out.iterations;
  } else {
    tried = "the solve on N = " + std::to_string(Nc) + " first: " + coarse.message;
  }
  ShootingResult<Sch> out = solve_bvp_with<Sch>(bvp, guess, direct);
  out.detail = (out.detail.empty() ? "" : out.detail + "; ") + "solved from the guess after a start from a coarser grid failed (" +
               tried + ")";
  out.iterations += fine_iterations;
  out.coarse_iterations = coarse_iterations;
  return finish(std::move(out));
}

}  // namespace lpshoot
