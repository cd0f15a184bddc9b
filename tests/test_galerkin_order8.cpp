// Galerkin order 8 (degree 5: two bubbles per interval, four Gauss points, METHOD.md §9) on the
// beanie, with the library's own checks at degrees 3 and 4 (galerkin_beanie_checks.hpp,
// galerkin_group_checks.hpp): the discrete momentum map along a flow with non-zero multipliers,
// the flow's sensitivities and the shooting Jacobian against finite differences, the step and the
// end rows from interval Hessians against nested duals. Label "order8": these instances take
// gigabytes to compile under the sanitizers, so the checked build leaves them out; the Release
// suite runs them. Order 8's convergence is tested on both paper examples through the CLI
// (tests/cli, Sweep.GalerkinEightReachesOrderEightOnBothPaperExamples) and on the electron in
// test_galerkin_electron.cpp.
#include "galerkin_beanie_checks.hpp"
#include "galerkin_group_checks.hpp"

#include <gtest/gtest.h>

using namespace lpshoot::test_support;

TEST(GalerkinOrderEight, MomentumIsConservedToRoundoffWithNonZeroMultipliers) { check_momentum_conserved<5>(); }
TEST(GalerkinOrderEight, FlowSensitivityMatchesFiniteDifferences) { check_flow_sensitivity<5>(); }
TEST(GalerkinOrderEight, ShootingJacobianMatchesFiniteDifferences) { check_shooting_jacobian<5>(); }
TEST(GalerkinOrderEight, StepFromIntervalHessiansMatchesNestedDuals) { expect_same_step<5>(0.05); }
TEST(GalerkinOrderEight, EndRowsMatchNestedDuals) { expect_same_beanie_end_rows<5>(0.5); }
