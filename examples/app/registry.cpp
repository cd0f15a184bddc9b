// The registered problems (problem.hpp). Guarded by a mutex: the Python module loads problems of
// one's own with the GIL released, while other threads look problems up.
#include "problem.hpp"

#include <algorithm>
#include <mutex>

namespace lpshoot::app {
namespace {
std::vector<const Problem*>& registry() {
  static std::vector<const Problem*> problems;  // filled by static registrations, before main
  return problems;
}
std::vector<std::string>& errors() {
  static std::vector<std::string> e;
  return e;
}
std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
const Problem* find_unlocked(const std::string& name) {
  for (const Problem* p : registry())
    if (p->descriptor().name == name) return p;
  return nullptr;
}
}  // namespace

void register_problem(const Problem& problem) {
  const std::lock_guard<std::mutex> lock(registry_mutex());
  const std::string& name = problem.descriptor().name;
  if (const std::string why = problem.definition_error(); !why.empty()) {
    errors().push_back("problem \"" + name + "\": " + why);
    return;
  }
  if (name.empty()) {
    errors().push_back("a problem without a name (set the descriptor's name)");
    return;
  }
  if (find_unlocked(name)) {
    errors().push_back("problem \"" + name + "\" is registered twice (problem names must be unique)");
    return;
  }
  auto& r = registry();
  r.push_back(&problem);
  std::sort(r.begin(), r.end(), [](const Problem* a, const Problem* b) { return a->descriptor().name < b->descriptor().name; });
}

const Problem* find_problem(const std::string& name) {
  const std::lock_guard<std::mutex> lock(registry_mutex());
  return find_unlocked(name);
}

std::vector<const Problem*> registered_problems() {
  const std::lock_guard<std::mutex> lock(registry_mutex());
  return registry();
}

std::vector<std::string> registration_errors() {
  const std::lock_guard<std::mutex> lock(registry_mutex());
  return errors();
}

}  // namespace lpshoot::app
