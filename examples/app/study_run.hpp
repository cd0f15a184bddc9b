// Running a study (study.hpp) on a pool of threads, resumably, one shard of it or all; merging
// shards; the study's files: study.jsonl (one row per point, appended as points finish: the
// record a rerun resumes from), study.csv, study.json (a summary), study_spec.json (what the
// rows belong to), and the plots study_pareto.png (error against time per scheme) and
// study_cost.png (cost over the first axis, one line per value of the second).
#pragma once

#include "output.hpp"
#include "study.hpp"

#include <functional>

namespace lpshoot::app {

struct StudyOptions {
  std::string out;       // the study's directory
  int threads = 0;       // points solved at once; 0: one per core
  int shard = 0;         // run the points i with i % shards == shard
  int shards = 1;
  bool plot = true;
};

struct StudyProgress {
  size_t done = 0, total = 0, failures = 0;  // this run's points (the skipped ones not counted)
  double elapsed_s = 0, remaining_s = 0;
};

struct StudyOutcome {
  size_t points = 0;    // the points of this shard (or of the merged study)
  size_t run = 0;       // solved in this run
  size_t skipped = 0;   // found done in study.jsonl
  size_t failures = 0;  // rows whose status is not "converged"
  Written written;
};

// Runs the points `todo`, handing each row to `record` as it finishes (record may be called from
// any thread; it serialises itself). `checkpoint` throws Interrupted when the study must stop.
using StudyRecorder = std::function<void(StudyRow)>;
using StudyExecutor = std::function<void(const Study& study, const std::vector<size_t>& todo, const StudyRecorder& record,
                                         const Progress& checkpoint)>;

// The local executor: a pool of `threads` threads (0: one per core), one point per thread.
StudyExecutor thread_pool_executor(int threads);

// Runs the shard's points that study.jsonl in options.out does not hold yet (on `executor`,
// default the thread pool), then writes the study's files. A directory holding another study's
// rows is refused (OutputError). Throws Interrupted after SIGINT/SIGTERM once the running points
// are done: the rows kept in study.jsonl make a rerun complete the study.
StudyOutcome run_study(const Study& study, const StudyOptions& options,
                       const std::function<void(const StudyProgress&)>& progress, const StudyExecutor& executor = {});

// Joins the rows of shard directories of one study into `out` (and its files).
StudyOutcome merge_studies(const std::vector<std::string>& dirs, const std::string& out, bool plot);

}  // namespace lpshoot::app
