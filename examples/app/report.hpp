// The JSON account of a run or a sweep: report.json and sweep.json (output.cpp adds the files
// written and the warnings), and the Python module's result.report.
#pragma once

#include "sweep.hpp"

#include <nlohmann/json_fwd.hpp>

namespace lpshoot::app {

// Everything report.json says about a run, the effective scene last. Non-finite numbers are null.
nlohmann::ordered_json run_report(const Scene& scene, const RunRecord& run);
// Everything sweep.json says about a sweep, the effective scene last.
nlohmann::ordered_json sweep_report(const Scene& scene, const SweepRecord& sweep);

}  // namespace lpshoot::app
