// The registered problems (problem.hpp).
#include "problem.hpp"

#include <algorithm>
#include <stdexcept>

namespace lpshoot::app {
namespace {
std::vector<const Problem*>& registry() {
  static std::vector<const Problem*> problems;  // filled by static registrations, before main
  return problems;
}
}  // namespace

void register_problem(const Problem& problem) {
  if (find_problem(problem.descriptor().name))
    throw std::logic_error("problem '" + problem.descriptor().name + "' is registered twice");
  auto& r = registry();
  r.push_back(&problem);
  std::sort(r.begin(), r.end(), [](const Problem* a, const Problem* b) { return a->descriptor().name < b->descriptor().name; });
}

const Problem* find_problem(const std::string& name) {
  for (const Problem* p : registry())
    if (p->descriptor().name == name) return p;
  return nullptr;
}

std::vector<const Problem*> registered_problems() { return registry(); }

}  // namespace lpshoot::app
