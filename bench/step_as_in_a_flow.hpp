// Step 2 of the paper scheme as a flow with sensitivities takes it (bench_step, bench_ratios):
// windows a_{n-k} .. a_{n-1}'s Hessians carried from the previous steps (step_window_hessian.hpp),
// a_n's computed; Newton starts with chord iterations on the previous step's factored matrix
// (newton.hpp), here the same step's; the part of E_n from a_{n-k} .. a_{n-1} comes from their
// carried gradients, as DiscreteFlow::run passes the carry.
#pragma once

#include <lpshoot/core/lpshoot.hpp>

namespace lpshoot::bench {

template <class P>
class StepAsInAFlow {
 public:
  StepAsInAFlow(const P& problem, const FlowState<P>& s, double h) : problem_(problem), s_(s), h_(h) {
    solve_step(problem_, h_, s_, 2, opt_, z_);
    step_sensitivity(problem_, h_, s_, z_, &previous_, nullptr, &carry_, 2);
  }
  // Solves the step again from the carried state and returns its sensitivity; `iterations`: Newton's.
  Eigen::Matrix<double, Dims<P>::unknowns, Dims<P>::state> operator()(int* iterations = nullptr) {
    ChordMatrix<Dims<P>::unknowns> chord = previous_;
    const StepReport r = solve_step(problem_, h_, s_, 2, opt_, z_, &chord, &carry_);
    if (iterations) *iterations = r.iterations;
    return step_sensitivity(problem_, h_, s_, z_, &chord, nullptr, &carry_, 2);
  }

 private:
  const P problem_;
  const FlowState<P> s_;
  const double h_;
  const NewtonOptions opt_;
  StepUnknowns<P> z_;
  WindowHessianCarry<P> carry_;
  ChordMatrix<Dims<P>::unknowns> previous_;
};

}  // namespace lpshoot::bench
