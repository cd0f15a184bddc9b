// A spherical pendulum steered with minimum effort (not in the paper; issue 10's example of a
// problem added as one file). A mass m on a rod of length l, polar angle φ from the downward
// vertical, azimuth θ. Rotations about the vertical are a symmetry: G = SO(2) moves θ, the shape
// is φ, Ω = θ' (no connection). A torque u drives φ only:
//   u = m l² (φ'' - sin φ cos φ Ω²) + m g l sin φ,   ℓ = ½ u²,
// and the azimuth moves freely, so the vertical angular momentum m l² sin²φ Ω is conserved —
// imposed as the constraint χ = d/dt(sin²φ Ω) = sin²φ Ω' + 2 sin φ cos φ φ' Ω = 0.
// The discrete momentum map of the scheme (J) is conserved to roundoff; the mechanical one
// (P = m l² sin²φ Ω) to the scheme's order.
#include <lpshoot/app/model_problem.hpp>

#include <cmath>

namespace lpshoot::app {
namespace {

struct SphericalPendulum {
  using Group = SO2;
  static constexpr int shape_dim = 1;
  static constexpr int num_constraints = 1;
  double m = 1.0, l = 1.0, g = 9.81;

  template <class T>
  T control(const Jet<SphericalPendulum, T>& q) const {
    using std::cos, std::sin;
    const T s = sin(q.p(0)), c = cos(q.p(0)), w = q.Omega(0);
    return (m * l * l) * (q.ddp(0) - s * c * w * w) + (m * g * l) * s;
  }
  template <class T>
  T lagrangian(const Jet<SphericalPendulum, T>& q) const {
    const T u = control(q);
    return 0.5 * u * u;
  }
  template <class T>
  Vec<T, 1> constraints(const Jet<SphericalPendulum, T>& q) const {
    using std::cos, std::sin;
    const T s = sin(q.p(0)), c = cos(q.p(0));
    return Vec<T, 1>(s * s * q.dOmega(0) + 2.0 * s * c * q.dp(0) * q.Omega(0));
  }
};

ProblemDescriptor spherical_pendulum_descriptor() {
  ProblemDescriptor d;
  d.name = "spherical_pendulum";
  d.summary = "a spherical pendulum steered in its polar angle with minimum torque, the azimuth moving freely";
  d.parameters = {number_parameter("m", 1.0, "mass").positive(), number_parameter("l", 1.0, "rod length").positive(),
                  number_parameter("g", 9.81, "gravity").range(0.0, 1e3)};
  d.shape = {"phi"};
  d.velocity = {"phi_dot"};
  d.group = {"theta"};
  d.omega = {"Omega"};
  d.boundary = {{"phi", NodePart::Shape, 0, 1, false, "", ""},
                {"phi_dot", NodePart::Velocity, 0, 1, false, "phi", "is given without phi (give phi too, or neither)"},
                {"theta", NodePart::Group, 0, 1, false, "", ""},
                {"Omega", NodePart::Omega, 0, 1, false, "", ""}};
  d.outputs = {"u"};
  d.plots = {{"polar and azimuth angles", "t", {"phi", "theta"}, false},
             {"azimuthal rate", "t", {"Omega"}, false},
             {"torque u", "t", {"u"}, false}};
  return d;
}

ModelProblem<SphericalPendulum> make_problem() {
  ModelProblem<SphericalPendulum> p(spherical_pendulum_descriptor(), [](const ParameterValues& v) {
    return SphericalPendulum{v.number("m"), v.number("l"), v.number("g")};
  });
  p.outputs = [](const SphericalPendulum& m, const Jet<SphericalPendulum, double>& q) {
    return std::vector<double>{m.control(q)};
  };
  p.physical_momentum = [](const SphericalPendulum& m, const SO2::Element<double>&, const Jet<SphericalPendulum, double>& q) {
    const double s = std::sin(q.p(0));
    return Vec<double, 1>(m.m * m.l * m.l * s * s * q.Omega(0));
  };
  return p;
}

const ModelProblem<SphericalPendulum> spherical_pendulum = make_problem();
LPSHOOT_REGISTER_PROBLEM(spherical_pendulum);

}  // namespace
}  // namespace lpshoot::app
