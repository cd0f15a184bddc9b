// `lpshoot study STUDY.json [--out DIR] [--threads N] [--shard i/K]` and `lpshoot study merge
// DIR... --out DIR` (main.cpp parses the command line; README "Studies").
#pragma once

#include <string>
#include <vector>

namespace lpshoot::app {

struct StudyCommand {
  std::vector<std::string> args;  // the study file, or "merge" and the shard directories
  std::string out, shard;         // shard: "i/K" or empty
  int threads = 0;
  double rank_timeout_s = 60;  // under mpirun: a rank silent this long while holding points is lost
  bool plot = true, progress = false, quiet = false;
};

// Runs the command, prints its outcome; the exit code: 0 every point converged, 1 some did not
// (or were invalid), 2 a bad study file or command line, 3 results not writable, 130/143
// interrupted (the rows done are kept).
int run_study_command(const StudyCommand& c);

}  // namespace lpshoot::app
