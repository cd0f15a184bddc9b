// A problem descriptor (issue 10): what the application needs to know about a problem to read
// its scenes, name its outputs and plot them, stated next to the problem's struct in plain C++.
// The scene reader (scene.cpp) validates "parameters" and "boundary" against it; the
// runner (model_problem.hpp) names the trajectory's columns from it.
#pragma once

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace lpshoot::app {

// One entry under "parameters": a number, an array of numbers of fixed size, or a choice among
// words. `key` is a dotted path for nested objects ("potential.amplitude").
struct ParameterSpec {
  enum class Kind { Number, Array, Choice };
  std::string key;
  Kind kind = Kind::Number;
  std::vector<double> value;         // the default: one number, or the array
  std::vector<std::string> choices;  // Choice: the allowed words, the first is the default
  double min = -std::numeric_limits<double>::infinity(), max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;  // min < x rather than min <= x
  std::string help;

  ParameterSpec& positive() { return min = 0, min_exclusive = true, *this; }
  ParameterSpec& range(double lo, double hi) { return min = lo, max = hi, min_exclusive = false, *this; }
};

inline ParameterSpec number_parameter(std::string key, double value, std::string help) {
  return {std::move(key), ParameterSpec::Kind::Number, {value}, {}, -std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity(), false, std::move(help)};
}
inline ParameterSpec array_parameter(std::string key, std::vector<double> value, std::string help) {
  return {std::move(key), ParameterSpec::Kind::Array, std::move(value), {}, -std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity(), false, std::move(help)};
}
inline ParameterSpec choice_parameter(std::string key, std::vector<std::string> choices, std::string help) {
  return {std::move(key), ParameterSpec::Kind::Choice, {}, std::move(choices), -std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity(), false, std::move(help)};
}

// The four kinds of node data of the Galerkin schemes (METHOD.md §9): shape positions p, their
// velocities p', the reduced group velocity Ω and the group element g (in its natural
// coordinates, group_coordinates.hpp).
enum class NodePart { Shape, Velocity, Omega, Group };
const char* node_part_name(NodePart part);  // "shape", "velocity", "Omega", "group" (descriptor_check.cpp)

// One entry under "boundary.initial" / "boundary.final": `size` consecutive components of one
// part of the end node's data, a number when size is 1, else an array. A missing entry is free
// and gets its natural boundary condition. `requires` names another entry that must be given
// with this one at the same end (`requires_message` says why, as the error message).
struct BoundarySpec {
  std::string key;
  NodePart part = NodePart::Shape;
  int first = 0, size = 1;
  bool array = false;
  std::string requires, requires_message;
};

// A plot panel of trajectory.png: y columns against an x column (equal axes for a path).
struct PlotPanel {
  std::string title, x;
  std::vector<std::string> y;
  bool equal_axes = false;
};

// A choice among words under "scheme" that only the paper's discretization has (e.g. the beanie's
// constraints); the first word is the default.
struct SchemeOption {
  std::string key;
  std::vector<std::string> choices;
};

struct ProblemDescriptor {
  std::string name, summary;
  std::vector<ParameterSpec> parameters;
  // Column names: one per shape component, velocity, group coordinate and Ω component.
  std::vector<std::string> shape, velocity, group, omega;
  std::vector<BoundarySpec> boundary;
  std::vector<std::string> outputs;  // derived columns per node (controls, ...), model_problem.hpp
  std::vector<PlotPanel> plots;      // empty: the shape, the group coordinates and the outputs against t
  // The paper's nodal windows (METHOD.md §2) need a discrete form of the problem: its order k,
  // 0 when the problem has only the continuous form (Galerkin schemes only).
  int paper_order = 0;
  // The paper's windows derived from the continuous model (ModelProblem, core/paper_windows.hpp)
  // rather than a hand-written L_d: offered as a second-order reference, Galerkin stays the default.
  bool paper_derived = false;
  std::vector<SchemeOption> paper_options;
  // The highest Galerkin order compiled in: 6, or 8 (ModelProblem<Model, 8> sets it).
  int galerkin_max_order = 6;
  // false: a free motion from initial data (`lpshoot simulate`, the paper's windows of order
  // paper_order) rather than an optimal control problem (`lpshoot solve`).
  bool optimal_control = true;
  // A free motion's initial data: the names of its configuration coordinates. Under
  // boundary.initial the scene gives configurations [q_0, q_1], or position and velocity
  // (q_1 = q_0 + h q'(0), the paper's first-order closure), each with these components.
  std::vector<std::string> configuration;
};

// A scene's parameters, validated: every key of the descriptor has a value (default or given).
struct ParameterValues {
  std::map<std::string, std::vector<double>> numbers;  // Number (size 1) and Array
  std::map<std::string, std::string> words;            // Choice
  std::vector<std::string> given;                      // the keys the scene states explicitly

  double number(const std::string& key) const { return numbers.at(key).at(0); }
  const std::vector<double>& array(const std::string& key) const { return numbers.at(key); }
  const std::string& word(const std::string& key) const { return words.at(key); }
  bool is_given(const std::string& key) const {
    for (const auto& k : given)
      if (k == key) return true;
    return false;
  }
};

// One end's boundary data by descriptor key; a key absent is free.
struct BoundaryValues {
  std::map<std::string, std::vector<double>> given;
  bool has(const std::string& key) const { return given.count(key) > 0; }
  std::optional<double> scalar(const std::string& key) const {
    const auto it = given.find(key);
    return it == given.end() ? std::nullopt : std::optional<double>(it->second.at(0));
  }
};

// Component `index` of a node part at one end, when the end gives it (through whichever
// boundary entry covers it).
inline std::optional<double> boundary_component(const ProblemDescriptor& d, const BoundaryValues& b, NodePart part,
                                                int index) {
  for (const auto& spec : d.boundary) {
    if (spec.part != part || index < spec.first || index >= spec.first + spec.size || !b.has(spec.key)) continue;
    return b.given.at(spec.key).at(index - spec.first);
  }
  return std::nullopt;
}

// Where a boundary component is described in messages: "initial psi", "terminal x2".
inline std::string boundary_name(const ProblemDescriptor& d, bool initial, NodePart part, int index) {
  const std::vector<std::string>& names = part == NodePart::Shape      ? d.shape
                                          : part == NodePart::Velocity ? d.velocity
                                          : part == NodePart::Omega    ? d.omega
                                                                       : d.group;
  return std::string(initial ? "initial " : "terminal ") + names.at(index);
}

// The number of components of each node part, in NodePart order (shape, velocity, Ω, group).
struct PartSizes {
  int shape, velocity, omega, group;
};

// Why a descriptor contradicts itself or its model's dimensions (a boundary entry outside its
// part, a "requires" naming no entry, a default outside its range, a plot of an unknown column),
// or "" (descriptor_check.cpp).
std::string descriptor_error(const ProblemDescriptor& d, PartSizes sizes);

}  // namespace lpshoot::app
