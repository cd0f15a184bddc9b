// The beanie scene on the order-6 Galerkin scheme (one translation unit per degree: parallel builds).
#include "run_beanie_galerkin.hpp"

namespace lpshoot::app {
template RunRecord solve_beanie_galerkin_on<4>(const Scene& s, const Progress& progress);
}  // namespace lpshoot::app
