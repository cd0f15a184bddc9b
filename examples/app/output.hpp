// Results on disk: DIR/report.json, DIR/trajectory.csv, DIR/momentum.csv and gnuplot PNGs for a
// run; DIR/sweep.json, DIR/sweep.csv and DIR/sweep_error_time.png for a sweep. All are written
// into an OutputDir's staging directory, which then replaces DIR as a whole; a failed run writes
// only its report (saying it failed).
#pragma once

#include "output_dir.hpp"
#include "sweep.hpp"

namespace lpshoot::app {

struct Written {
  std::vector<std::string> files;
  std::vector<std::string> warnings;  // e.g. gnuplot missing: plots skipped
};

// Write, then commit OUT. Throw OutputError when a file cannot be written (OUT keeps its
// previous contents) and Interrupted when a signal arrives while gnuplot runs.
Written write_run(const Scene& scene, const RunRecord& run, OutputDir& out, bool plot);
Written write_sweep(const Scene& scene, const SweepRecord& sweep, OutputDir& out, bool plot);
// The report of a run stopped by SIGINT/SIGTERM (report.json, or sweep.json for a sweep).
Written write_interrupted(const Scene& scene, const std::string& command, OutputDir& out, const std::string& why,
                          double wall_time_s);

}  // namespace lpshoot::app
