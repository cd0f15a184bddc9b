// The registered problems described from their descriptors (`lpshoot problems`, and the Python
// module's lpshoot.problems()): text for people, JSON for programs.
#pragma once

#include "problem.hpp"

#include <string>
#include <vector>

namespace lpshoot::app {

std::string problems_text(const std::vector<const Problem*>& problems);
std::string problems_json(const std::vector<const Problem*>& problems);  // an array, one object per problem

}  // namespace lpshoot::app
