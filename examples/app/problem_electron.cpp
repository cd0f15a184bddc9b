// The electron in a magnetic field (paper §4.1.1, METHOD.md §6.1): its descriptor, its
// continuous model for the Galerkin schemes and its discrete form for the paper's windows.
#include "model_problem.hpp"
#include "paper_problems.hpp"

namespace lpshoot::app {

// The order-8 solve is compiled apart (problem_electron_order8.cpp), in parallel with this file and
// within the memory of orders 4 and 6 (one file with all three: 1.5x the time, 5.5 GB).
extern template RunRecord ModelProblem<problems::ElectronModel, 8, false>::solve_galerkin<5>(const Scene&, const Progress&) const;
namespace {

ProblemDescriptor electron_descriptor() {
  ProblemDescriptor d;
  d.name = "electron";
  d.summary = "minimum-energy transfer of an electron in a constant magnetic field and the trap potential |x|^2";
  d.parameters = {number_parameter("m", 1.0, "mass").positive(),
                  number_parameter("e_over_c", 1.0, "charge over the speed of light"),
                  array_parameter("B", {0.0, 0.0, 1.0}, "magnetic field"),
                  number_parameter("potential", 1.0, "trap strength: phi(x) = potential |x|^2")};
  d.shape = {"x1", "x2", "x3"};
  d.velocity = {"v1", "v2", "v3"};
  d.boundary = {{"position", NodePart::Shape, 0, 3, true, "", ""},
                {"velocity", NodePart::Velocity, 0, 3, true, "position",
                 "a velocity without a position is not supported (give the position too, or neither)"}};
  d.outputs = {"u1", "u2", "u3"};
  d.plots = {{"plane path", "x1", {"x2"}, true}, {"position", "t", {"x1", "x2", "x3"}, false},
             {"control u", "t", {"u1", "u2", "u3"}, false}};
  d.paper_order = problems::Electron::order;
  return d;
}

class ElectronProblem : public ModelProblem<problems::ElectronModel, 8, false> {
 public:
  ElectronProblem()
      : ModelProblem(electron_descriptor(), [](const ParameterValues& v) { return problems::model_of(electron_of(v)); }) {
    outputs = [](const problems::ElectronModel& m, const Jet<problems::ElectronModel, double>& q) {
      const Eigen::Vector3d u = m.control(q);
      return std::vector<double>{u(0), u(1), u(2)};
    };
    guess4 = [](const GalerkinBVP<Scheme<3>>& bvp, const Scene& s) {
      return problems::electron_galerkin_guess<3>(bvp, electron_boundary(s.start), electron_boundary(s.end));
    };
    guess6 = [](const GalerkinBVP<Scheme<4>>& bvp, const Scene& s) {
      return problems::electron_galerkin_guess<4>(bvp, electron_boundary(s.start), electron_boundary(s.end));
    };
    guess8 = [](const GalerkinBVP<Scheme<5>>& bvp, const Scene& s) {
      return problems::electron_galerkin_guess<5>(bvp, electron_boundary(s.start), electron_boundary(s.end));
    };
  }
  ExactReference exact_reference(const Scene& s, const std::vector<double>& times) const override {
    return electron_exact_reference(s, times);
  }

 protected:
  RunRecord solve_paper(const Scene& s, const Progress& progress) const override { return solve_electron(s, progress); }
  std::string check_paper(const Scene& s) const override {
    return counting_error([&] {
      return problems::electron_bvp(electron_of(s.parameters), s.T, s.N, electron_boundary(s.start),
                                    electron_boundary(s.end), s.closure);
    });
  }
};

const ElectronProblem electron;
LPSHOOT_REGISTER_PROBLEM(electron);

}  // namespace
}  // namespace lpshoot::app
