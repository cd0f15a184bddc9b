// A problem of one's own, as one file (README, "A problem of your own"): a mass on an isotropic
// spring in the plane, steered between two states with minimum effort.
//   x ∈ R², u = x'' + ω² x (the force per unit mass that the spring does not supply), ℓ = ½ |u|².
// No symmetry is used (G is the trivial group). Its optimal motions solve (d²/dt² + ω²)² x = 0,
// so x(t) = (a + b t) cos ωt + (c + d t) sin ωt per component: an exact answer to test against.
//
//   lpshoot solve --problem examples/plugins/oscillator.cpp examples/plugins/oscillator.json
#include <lpshoot/app/model_problem.hpp>

namespace {

using namespace lpshoot;
using namespace lpshoot::app;

// 1. The model: the reduced Lagrangian on the shape's jet (x, x', x''), in any scalar type T.
struct Oscillator {
  using Group = Trivial;
  static constexpr int shape_dim = 2;
  static constexpr int num_constraints = 0;
  double omega = 1.0;

  template <class T>
  Vec<T, 2> control(const Jet<Oscillator, T>& q) const {
    return Vec<T, 2>(q.ddp + (omega * omega) * q.p);
  }
  template <class T>
  T lagrangian(const Jet<Oscillator, T>& q) const {
    return 0.5 * control(q).squaredNorm();
  }
};

// 2. The descriptor: names for the scene and the CSV.
ProblemDescriptor oscillator_descriptor() {
  ProblemDescriptor d;
  d.name = "oscillator";
  d.summary = "a mass on a planar spring steered between two states with minimum effort";
  d.parameters = {number_parameter("omega", 1.0, "the spring's angular frequency").positive()};
  d.shape = {"x1", "x2"};
  d.velocity = {"v1", "v2"};
  d.boundary = {{"position", NodePart::Shape, 0, 2, true, "", ""},
                {"velocity", NodePart::Velocity, 0, 2, true, "", ""}};
  d.outputs = {"u1", "u2"};
  d.plots = {{"path", "x1", {"x2"}, true}, {"control u", "t", {"u1", "u2"}, false}};
  return d;
}

// 3. The problem: the model built from the scene's parameters, the control as output columns.
ModelProblem<Oscillator> make_oscillator() {
  ModelProblem<Oscillator> p(oscillator_descriptor(),
                             [](const ParameterValues& v) { return Oscillator{v.number("omega")}; });
  p.outputs = [](const Oscillator& m, const Jet<Oscillator, double>& q) {
    const Vec<double, 2> u = m.control(q);
    return std::vector<double>{u(0), u(1)};
  };
  return p;
}

const ModelProblem<Oscillator> oscillator = make_oscillator();
LPSHOOT_REGISTER_PROBLEM(oscillator);

}  // namespace
