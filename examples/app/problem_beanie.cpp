// Elroy's beanie (paper §4.1.2, METHOD.md §6.2), steered by its rotor with minimum effort: its
// descriptor, its continuous model for the Galerkin schemes and its discrete form for the
// paper's windows (with the paper's or the exact-rotation constraints).
#include "model_problem.hpp"
#include "paper_problems.hpp"

namespace lpshoot::app {

// The order-8 solve is compiled apart (problem_beanie_order8.cpp), in parallel with this file and
// within the memory of orders 4 and 6 (one file with all three: 1.5x the time, 5.5 GB).
extern template RunRecord ModelProblem<problems::BeanieModel, 8, false>::solve_galerkin<5>(const Scene&, const Progress&) const;

const ProblemDescriptor& beanie_descriptor() {
  static const ProblemDescriptor d = [] {
    ProblemDescriptor d;
    d.name = "beanie";
    d.summary = "Elroy's beanie: a planar rigid body with a rotor, steered by the rotor with minimum effort";
    d.parameters = {number_parameter("m", 1.0, "mass").positive(),
                    number_parameter("I1", 1.0, "body inertia").positive(),
                    number_parameter("I2", 1.0, "rotor inertia").positive(),
                    choice_parameter("potential.type", {"none", "cosine"}, "shape potential V(psi)"),
                    number_parameter("potential.amplitude", 0.0, "V(psi) = amplitude (1 - cos psi) (type cosine)")};
    d.shape = {"psi"};
    d.velocity = {"psi_dot"};
    d.group = {"x", "y", "theta"};
    d.omega = {"Omega1", "Omega2", "Omega3"};
    d.boundary = {{"psi", NodePart::Shape, 0, 1, false, "", ""},
                  {"psi_dot", NodePart::Velocity, 0, 1, false, "psi", "is given without psi (give psi too, or neither)"},
                  {"theta", NodePart::Group, 2, 1, false, "", ""},
                  {"x", NodePart::Group, 0, 1, false, "", ""},
                  {"y", NodePart::Group, 1, 1, false, "", ""},
                  {"Omega1", NodePart::Omega, 0, 1, false, "", ""},
                  {"Omega2", NodePart::Omega, 1, 1, false, "", ""},
                  {"Omega3", NodePart::Omega, 2, 1, false, "", ""}};
    d.outputs = {"u"};
    d.plots = {{"plane path", "x", {"y"}, true}, {"shape and orientation", "t", {"psi", "theta"}, false},
               {"control u", "t", {"u"}, false}};
    d.paper_order = problems::BeanieControl::order;
    d.paper_options = {{"constraints", {"exact_rotation", "paper"}}};
    return d;
  }();
  return d;
}

namespace {

class BeanieProblem : public ModelProblem<problems::BeanieModel, 8, false> {
 public:
  BeanieProblem()
      : ModelProblem(beanie_descriptor(), [](const ParameterValues& v) { return problems::BeanieModel{beanie_parameters(v)}; }) {
    outputs = [](const problems::BeanieModel& m, const Jet<problems::BeanieModel, double>& q) {
      return std::vector<double>{m.control(q)};
    };
    // The free beanie's spatial momentum Ad*_{g^-1} (m Ω1, m Ω2, (I1 + I2) Ω3): conserved to the
    // scheme's order, its equations being the constraints imposed at the Gauss points.
    physical_momentum = [](const problems::BeanieModel& m, const SE2::Element<double>& g,
                           const Jet<problems::BeanieModel, double>& q) {
      const Eigen::Vector3d& Om = q.Omega;
      const Eigen::Vector3d M(m.par.m * Om(0), m.par.m * Om(1), (m.par.I1 + m.par.I2) * Om(2));
      return Eigen::Vector3d(SE2::Ad(SE2::inverse(g)).transpose() * M);
    };
    guess4 = [](const GalerkinBVP<Scheme<3>>& bvp, const Scene& s) {
      return problems::beanie_galerkin_guess<3>(bvp, beanie_boundary(s.start), beanie_boundary(s.end));
    };
    guess6 = [](const GalerkinBVP<Scheme<4>>& bvp, const Scene& s) {
      return problems::beanie_galerkin_guess<4>(bvp, beanie_boundary(s.start), beanie_boundary(s.end));
    };
    guess8 = [](const GalerkinBVP<Scheme<5>>& bvp, const Scene& s) {
      return problems::beanie_galerkin_guess<5>(bvp, beanie_boundary(s.start), beanie_boundary(s.end));
    };
  }
  std::optional<std::pair<std::string, std::string>> check_parameters(const ParameterValues& v) const override {
    const bool cosine = v.word("potential.type") == "cosine";
    if (!cosine && v.is_given("potential.amplitude"))
      return std::make_pair(std::string("potential.amplitude"), std::string("is only used with type \"cosine\""));
    if (cosine && !v.is_given("potential.amplitude"))
      return std::make_pair(std::string("potential.amplitude"), std::string("missing (required with type \"cosine\")"));
    return std::nullopt;
  }

 protected:
  RunRecord solve_paper(const Scene& s, const Progress& progress) const override { return solve_beanie(s, progress); }
  std::string check_paper(const Scene& s) const override {
    problems::BeanieControl b;
    b.par = beanie_parameters(s.parameters);
    b.variant = beanie_constraints(s);
    return counting_error(
        [&] { return problems::beanie_bvp(b, s.T, s.N, beanie_boundary(s.start), beanie_boundary(s.end), s.closure); });
  }
};

const BeanieProblem beanie;
LPSHOOT_REGISTER_PROBLEM(beanie);

}  // namespace
}  // namespace lpshoot::app
