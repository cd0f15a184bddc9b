// The cart-pendulum moved by a horizontal force with minimum effort (a crane transfer; the
// library example's system, examples/library_example/cart_pendulum.cpp, as an optimal control
// problem). A pendulum (mass m, length l, angle ψ from the downward vertical) hangs from a cart
// (mass M) on a rail; a force u pushes the cart. G = R¹ moves the cart (x), the shape is ψ, and
// Ω = x'. From L = ½(M+m) x'² + m l cos ψ x'ψ' + ½ m l² ψ'² + m g l cos ψ:
//   u = (M+m) Ω' + m l (cos ψ ψ'' − sin ψ ψ'²),        ℓ = ½ u²,
// and the pendulum is not actuated, which is the constraint (its equation divided by m l)
//   χ = l ψ'' + cos ψ Ω' + g sin ψ = 0.
// The cart position does not enter ℓ or χ, so the scheme's momentum map J is conserved.
// The force column u: χ depends on ψ'' and ℓ couples ψ'' with Ω', so the discrete Legendre
// transform (which approximates ∂(ℓ + λ·χ)/∂ψ'') does not give ψ'' at the nodes; ψ'' and Ω'
// come from differentiating the node values instead (core/galerkin_flow.hpp, node_jets; the
// report says "outputs_from": "node_differences").
#include <lpshoot/app/model_problem.hpp>

#include <cmath>

namespace lpshoot::app {
namespace {

struct CartPendulum {
  using Group = Rn<1>;
  static constexpr int shape_dim = 1;
  static constexpr int num_constraints = 1;
  double M = 1.0, m = 0.5, l = 1.0, g = 9.81;

  template <class T>
  T control(const Jet<CartPendulum, T>& q) const {
    using std::cos, std::sin;
    return (M + m) * q.dOmega(0) + (m * l) * (cos(q.p(0)) * q.ddp(0) - sin(q.p(0)) * q.dp(0) * q.dp(0));
  }
  template <class T>
  T lagrangian(const Jet<CartPendulum, T>& q) const {
    const T u = control(q);
    return 0.5 * u * u;
  }
  template <class T>
  Vec<T, 1> constraints(const Jet<CartPendulum, T>& q) const {
    using std::cos, std::sin;
    return Vec<T, 1>(l * q.ddp(0) + cos(q.p(0)) * q.dOmega(0) + g * sin(q.p(0)));
  }
};

ProblemDescriptor cart_pendulum_descriptor() {
  ProblemDescriptor d;
  d.name = "cart_pendulum";
  d.summary = "a pendulum hung from a cart that a horizontal force moves with minimum effort (a crane transfer)";
  d.parameters = {number_parameter("M", 1.0, "cart mass").positive(), number_parameter("m", 0.5, "pendulum mass").positive(),
                  number_parameter("l", 1.0, "pendulum length").positive(),
                  number_parameter("g", 9.81, "gravity").range(0.0, 1e3)};
  d.shape = {"psi"};
  d.velocity = {"psi_dot"};
  d.group = {"x"};
  d.omega = {"v"};
  d.boundary = {{"psi", NodePart::Shape, 0, 1, false, "", ""},
                {"psi_dot", NodePart::Velocity, 0, 1, false, "psi", "is given without psi (give psi too, or neither)"},
                {"x", NodePart::Group, 0, 1, false, "", ""},
                {"v", NodePart::Omega, 0, 1, false, "", ""}};
  d.outputs = {"u"};
  d.plots = {{"cart position and pendulum angle", "t", {"x", "psi"}, false},
             {"cart and pendulum velocities", "t", {"v", "psi_dot"}, false},
             {"cart force u", "t", {"u"}, false}};
  return d;
}

ModelProblem<CartPendulum> make_problem() {
  ModelProblem<CartPendulum> p(cart_pendulum_descriptor(), [](const ParameterValues& v) {
    return CartPendulum{v.number("M"), v.number("m"), v.number("l"), v.number("g")};
  });
  p.outputs = [](const CartPendulum& m, const Jet<CartPendulum, double>& q) { return std::vector<double>{m.control(q)}; };
  return p;
}

const ModelProblem<CartPendulum> cart_pendulum = make_problem();
LPSHOOT_REGISTER_PROBLEM(cart_pendulum);

}  // namespace
}  // namespace lpshoot::app
