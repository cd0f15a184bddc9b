// The lpshoot core: Lie groups, the problem contracts (a discrete L_d for the paper's windows, or a
// continuous ℓ for the Galerkin schemes and, through PaperWindows, for the paper's windows), the
// derived discrete constrained higher-order Lagrange–Poincaré equations, the discrete flow maps
// and momentum.
#pragma once

#include "flow.hpp"
#include "galerkin_flow.hpp"
#include "groups.hpp"
#include "local_action.hpp"
#include "momentum.hpp"
#include "paper_windows.hpp"
#include "problem.hpp"
#include "step_solve.hpp"
