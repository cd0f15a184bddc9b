// Elroy's beanie's order-8 Galerkin solve (METHOD.md §9: quintic, four Gauss points), compiled apart
// from problem_beanie.cpp, which declares it extern.
#include "model_problem.hpp"
#include "paper_problems.hpp"

namespace lpshoot::app {

template RunRecord ModelProblem<problems::BeanieModel, 8, false>::solve_galerkin<5>(const Scene&, const Progress&) const;

}  // namespace lpshoot::app
