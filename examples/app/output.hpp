// Results on disk: DIR/report.json, DIR/trajectory.csv, DIR/momentum.csv and gnuplot PNGs for a
// run; DIR/sweep.json, DIR/sweep.csv and DIR/sweep_error_time.png for a sweep. Every file is
// written to a temporary name and renamed into place, so a reader never sees a partial file; a
// failed run writes only its report (saying it failed) and removes the previous run's results.
#pragma once

#include "sweep.hpp"

#include <stdexcept>

namespace lpshoot::app {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Written {
  std::vector<std::string> files;
  std::vector<std::string> warnings;  // e.g. gnuplot missing: plots skipped
};

// Throws OutputError when DIR cannot be created or written.
Written write_run(const Scene& scene, const RunRecord& run, const std::string& dir, bool plot);
Written write_sweep(const Scene& scene, const SweepRecord& sweep, const std::string& dir, bool plot);

}  // namespace lpshoot::app
