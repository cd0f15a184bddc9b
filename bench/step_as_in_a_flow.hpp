// Step 2 of the paper scheme as a flow with sensitivities takes it (bench_step, bench_ratios):
// windows a_{n-k} .. a_{n-1}'s Hessians carried from the previous steps (step_window_hessian.hpp),
// a_n's computed; Newton starts with chord iterations on the previous step's factored matrix
// (newton.hpp), here the same step's; the part of E_n from a_{n-k} .. a_{n-1} comes from their
// carried gradients, as DiscreteFlow::run passes the carry; a chord end predicted within the
// tolerance is confirmed at the sensitivity (confirm_predicted_step), as the flow does.
#pragma once

#include <lpshoot/core/lpshoot.hpp>

namespace lpshoot::bench {

template <class P>
class StepAsInAFlow {
 public:
  StepAsInAFlow(const P& problem, const FlowState<P>& s, double h) : problem_(problem), s_(s), h_(h) {
    solve_step(problem_, h_, s_, 2, NewtonOptions{}, z_);
    opt_.end_on_prediction = uses_window_hessians<P>();  // as DiscreteFlow::run with a seed
    step_sensitivity(problem_, h_, s_, z_, &previous_, nullptr, &carry_, 2);
  }
  // Solves the step again from the carried state and returns its sensitivity; `iterations`: Newton's.
  Eigen::Matrix<double, Dims<P>::unknowns, Dims<P>::state> operator()(int* iterations = nullptr) {
    ChordMatrix<Dims<P>::unknowns> chord = previous_;
    StepReport r = solve_step(problem_, h_, s_, 2, opt_, z_, &chord, &carry_);
    double condition = 0;
    auto dz = step_sensitivity(problem_, h_, s_, z_, &chord, &condition, &carry_, 2);
    if (r.predicted && condition <= opt_.max_condition &&
        !confirm_predicted_step(problem_, opt_, s_, chord, carry_, 2, z_)) {
      NewtonOptions again = opt_;
      again.end_on_prediction = false;
      const StepUnknowns<P> from = z_;
      r.iterations += solve_step(problem_, h_, s_, 2, again, z_, &chord, &carry_, &from).iterations;
      dz = step_sensitivity(problem_, h_, s_, z_, &chord, &condition, &carry_, 2);
    }
    if (iterations) *iterations = r.iterations;
    return dz;
  }

 private:
  const P problem_;
  const FlowState<P> s_;
  const double h_;
  NewtonOptions opt_;
  StepUnknowns<P> z_;
  WindowHessianCarry<P> carry_;
  ChordMatrix<Dims<P>::unknowns> previous_;
};

}  // namespace lpshoot::bench
