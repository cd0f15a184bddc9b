// `lpshoot problems` (describe.hpp): each problem's parameters with defaults and ranges, its
// boundary entries with the node data they fix, its columns and its schemes.
#include "describe.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>

namespace lpshoot::app {
namespace {

using json = nlohmann::ordered_json;

const char* kind_name(ParameterSpec::Kind k) {
  return k == ParameterSpec::Kind::Number ? "number" : k == ParameterSpec::Kind::Array ? "array" : "choice";
}

std::string number(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", x);
  return b;
}

std::string range_text(const ParameterSpec& p) {
  const bool lo = std::isfinite(p.min), hi = std::isfinite(p.max);
  if (!lo && !hi) return "";
  if (lo && !hi) return std::string(p.min_exclusive ? "> " : ">= ") + number(p.min);
  if (!lo) return "<= " + number(p.max);
  return "in " + std::string(p.min_exclusive ? "(" : "[") + number(p.min) + ", " + number(p.max) + "]";
}


json describe(const ProblemDescriptor& d) {
  json j;
  j["name"] = d.name;
  j["summary"] = d.summary;
  json params = json::array();
  for (const auto& p : d.parameters) {
    json e{{"key", p.key}, {"kind", kind_name(p.kind)}};
    if (p.kind == ParameterSpec::Kind::Choice) e["choices"] = p.choices, e["default"] = p.choices.front();
    else if (p.kind == ParameterSpec::Kind::Number) e["default"] = p.value.at(0);
    else e["default"] = p.value;
    if (std::isfinite(p.min)) e["min"] = p.min, e["min_exclusive"] = p.min_exclusive;
    if (std::isfinite(p.max)) e["max"] = p.max;
    e["help"] = p.help;
    params.push_back(e);
  }
  j["parameters"] = params;
  json boundary = json::array();
  for (const auto& b : d.boundary) {
    json e{{"key", b.key}, {"part", node_part_name(b.part)}, {"first", b.first}, {"size", b.size}, {"array", b.array}};
    if (!b.requires.empty()) e["requires"] = b.requires;
    boundary.push_back(e);
  }
  j["boundary"] = boundary;
  j["command"] = d.optimal_control ? "solve" : "simulate";
  if (!d.optimal_control) j["configuration"] = d.configuration;
  j["columns"] = {{"shape", d.shape}, {"velocity", d.velocity}, {"group", d.group}, {"omega", d.omega}, {"outputs", d.outputs}};
  j["schemes"] = scheme_names(d);
  if (d.paper_order > 0) j["paper_order"] = d.paper_order;
  if (d.paper_derived) j["paper_derived"] = true;  // the paper's windows from the continuous model
  return j;
}

}  // namespace

std::string problems_json(const std::vector<const Problem*>& problems) {
  json all = json::array();
  for (const Problem* p : problems) all.push_back(describe(p->descriptor()));
  return all.dump(2) + "\n";
}

std::string problems_text(const std::vector<const Problem*>& problems) {
  std::string out;
  for (const Problem* p : problems) {
    const ProblemDescriptor& d = p->descriptor();
    out += d.name + ": " + d.summary + "\n";
    std::string sc;
    for (const auto& s : scheme_names(d)) sc += (sc.empty() ? "" : ", ") + s;
    out += "  " + std::string(d.optimal_control ? "solve" : "simulate") + ", schemes: " + sc + "\n";
    if (!d.parameters.empty()) out += "  parameters:\n";
    for (const auto& q : d.parameters) {
      std::string def;
      if (q.kind == ParameterSpec::Kind::Choice) {
        for (const auto& c : q.choices) def += (def.empty() ? "" : " | ") + c;
      } else if (q.kind == ParameterSpec::Kind::Number) {
        def = number(q.value.at(0));
      } else {
        for (double x : q.value) def += (def.empty() ? "[" : ", ") + number(x);
        def += "]";
      }
      const std::string range = range_text(q);
      out += "    " + q.key + " = " + def + (range.empty() ? "" : " (" + range + ")") + "  " + q.help + "\n";
    }
    if (!d.boundary.empty()) out += "  boundary (under boundary.initial and boundary.final; missing = free):\n";
    for (const auto& b : d.boundary) {
      out += "    " + b.key + ": " + (b.array ? "array of " + std::to_string(b.size) : std::string("number")) + ", " +
             node_part_name(b.part);
      if (!b.requires.empty()) out += ", requires " + b.requires;
      out += "\n";
    }
    if (!d.configuration.empty()) {
      std::string q;
      for (const auto& c : d.configuration) q += (q.empty() ? "[" : ", ") + c;
      q += "]";
      out += "  initial data (under boundary.initial): configurations [q_0, q_1], or position and velocity; q = " + q + "\n";
    }
    std::string cols = "t";
    for (const auto* names : {&d.shape, &d.group, &d.omega, &d.velocity, &d.outputs})
      for (const auto& c : *names) cols += ", " + c;
    out += "  columns: " + cols + "\n";
  }
  return out;
}

}  // namespace lpshoot::app
