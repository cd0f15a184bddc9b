// A descriptor checked against itself and its model's dimensions (descriptor.hpp), when its
// problem is registered: a mistake in a problem's definition is reported by name before any scene.
#include "descriptor.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace lpshoot::app {
namespace {

int part_size(NodePart part, PartSizes n) {
  switch (part) {
    case NodePart::Shape: return n.shape;
    case NodePart::Velocity: return n.velocity;
    case NodePart::Omega: return n.omega;
    case NodePart::Group: return n.group;
  }
  return 0;
}

std::string parameter_error(const ParameterSpec& p) {
  const std::string where = "parameter \"" + p.key + "\": ";
  if (p.key.empty() || p.key.front() == '.' || p.key.back() == '.') return "a parameter with an empty key";
  switch (p.kind) {
    case ParameterSpec::Kind::Number:
      if (p.value.size() != 1) return where + "a number parameter needs exactly one default value";
      break;
    case ParameterSpec::Kind::Array:
      if (p.value.empty()) return where + "an array parameter needs a default array (its size is the array's size)";
      break;
    case ParameterSpec::Kind::Choice:
      if (p.choices.empty()) return where + "a choice parameter needs at least one word (the first is the default)";
      return "";
  }
  for (double x : p.value) {
    const bool below = p.min_exclusive ? !(x > p.min) : !(x >= p.min);
    if (!std::isfinite(x) || below || !(x <= p.max)) return where + "the default value lies outside its own range";
  }
  return "";
}

}  // namespace

const char* node_part_name(NodePart part) {
  switch (part) {
    case NodePart::Shape: return "shape";
    case NodePart::Velocity: return "velocity";
    case NodePart::Omega: return "Omega";
    case NodePart::Group: return "group";
  }
  return "";
}

std::string descriptor_error(const ProblemDescriptor& d, PartSizes sizes) {
  std::set<std::string> keys;
  for (const auto& p : d.parameters) {
    if (const std::string why = parameter_error(p); !why.empty()) return why;
    if (!keys.insert(p.key).second) return "parameter \"" + p.key + "\" is declared twice";
  }
  std::set<std::string> entries;
  for (const auto& b : d.boundary) {
    const std::string where = "boundary entry \"" + b.key + "\": ";
    if (b.key.empty()) return "a boundary entry with an empty key";
    if (!entries.insert(b.key).second) return where + "declared twice";
    const int n = part_size(b.part, sizes);
    if (b.size < 1 || b.first < 0 || b.first + b.size > n)
      return where + "components " + std::to_string(b.first) + ".." + std::to_string(b.first + b.size - 1) +
             " of the " + node_part_name(b.part) + " part, which has " + std::to_string(n) + " component(s)";
    if (!b.array && b.size != 1) return where + "a scalar entry (array = false) must cover exactly one component";
  }
  for (const auto& b : d.boundary)
    if (!b.requires.empty() && !entries.count(b.requires))
      return "boundary entry \"" + b.key + "\" requires \"" + b.requires + "\", which is not a boundary entry";
  std::set<std::string> columns{"t"};
  for (const auto* names : {&d.shape, &d.velocity, &d.group, &d.omega, &d.outputs})
    for (const auto& c : *names) {
      if (c.empty()) return "a column (shape, velocity, group, omega or output name) is empty";
      if (!columns.insert(c).second) return "column \"" + c + "\" is named twice";
    }
  for (const auto& panel : d.plots) {
    std::vector<std::string> used = panel.y;
    used.push_back(panel.x);
    for (const auto& c : used)
      if (!columns.count(c))
        return "plot \"" + panel.title + "\" shows column \"" + c + "\", which the problem does not have";
  }
  return "";
}

}  // namespace lpshoot::app
