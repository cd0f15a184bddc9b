// The lpshoot core: Lie groups, the problem contract, the derived discrete constrained
// higher-order Lagrange–Poincaré equations, the discrete flow map and momentum.
#pragma once

#include "flow.hpp"
#include "groups.hpp"
#include "local_action.hpp"
#include "momentum.hpp"
#include "problem.hpp"
#include "step.hpp"
