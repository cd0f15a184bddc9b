// The paper's problems in their discrete (nodal-window) form: scene values into the typed
// structs of examples/problems and the runners of the paper's scheme (run_electron.cpp,
// run_beanie.cpp, run_beanie_free.cpp). Their Galerkin schemes go through model_problem.hpp.
#pragma once

#include "run.hpp"

#include <lpshoot/problems/beanie_bvp.hpp>
#include <lpshoot/problems/electron_bvp.hpp>

namespace lpshoot::app {

inline problems::Electron electron_of(const ParameterValues& v) {
  problems::Electron e;
  e.mass = v.number("m");
  e.e_over_c = v.number("e_over_c");
  const auto& B = v.array("B");
  e.B = Eigen::Vector3d(B[0], B[1], B[2]);
  e.potential = v.number("potential");
  return e;
}

inline problems::ElectronBoundary electron_boundary(const BoundaryValues& b) {
  problems::ElectronBoundary e;
  e.free_position = !b.has("position");
  e.free_velocity = !b.has("velocity");
  if (!e.free_position) e.position = Eigen::Vector3d(b.given.at("position").data());
  if (!e.free_velocity) e.velocity = Eigen::Vector3d(b.given.at("velocity").data());
  return e;
}

inline problems::BeanieParameters beanie_parameters(const ParameterValues& v) {
  problems::BeanieParameters p;
  p.m = v.number("m");
  p.I1 = v.number("I1");
  p.I2 = v.number("I2");
  p.amplitude = v.word("potential.type") == "cosine" ? v.number("potential.amplitude") : 0.0;
  return p;
}

inline problems::BeanieBoundary beanie_boundary(const BoundaryValues& b) {
  problems::BeanieBoundary o;
  o.psi = b.scalar("psi"), o.psi_dot = b.scalar("psi_dot"), o.theta = b.scalar("theta");
  o.x = b.scalar("x"), o.y = b.scalar("y");
  o.Omega1 = b.scalar("Omega1"), o.Omega2 = b.scalar("Omega2"), o.Omega3 = b.scalar("Omega3");
  return o;
}

inline problems::BeanieConstraints beanie_constraints(const Scene& s) {
  const auto it = s.scheme_options.find("constraints");
  return it != s.scheme_options.end() && it->second == "paper" ? problems::BeanieConstraints::Paper
                                                                : problems::BeanieConstraints::ExactRotation;
}

RunRecord solve_electron(const Scene& s, const Progress& progress);
ExactReference electron_exact_reference(const Scene& s, const std::vector<double>& times);
RunRecord solve_beanie(const Scene& s, const Progress& progress);
RunRecord simulate_beanie_free(const Scene& s, const Progress& progress);

// The beanie's descriptor, whose parameters the free beanie's simulation shares.
const ProblemDescriptor& beanie_descriptor();

}  // namespace lpshoot::app
