// The electron scene on the order-4 Galerkin scheme (one translation unit per degree: parallel builds).
#include "run_electron_galerkin.hpp"

namespace lpshoot::app {
template RunRecord solve_electron_galerkin_on<3>(const Scene& s, const Progress& progress);
}  // namespace lpshoot::app
