// `lpshoot study` on the command line (study_cli.hpp): the roles under mpirun, messages and exit
// codes. The study itself is study_run.cpp; MPI is study_mpi.cpp.
#include "study_cli.hpp"

#include "interrupt.hpp"
#include "study_mpi.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>

namespace lpshoot::app {
namespace {

int fail_input(const std::string& what) {
  std::fprintf(stderr, "lpshoot: %s\n", what.c_str());
  return 2;
}

void print_files(const Written& w) {
  for (const auto& warning : w.warnings) std::fprintf(stderr, "lpshoot: warning: %s\n", warning.c_str());
  std::printf("wrote:");
  for (const auto& f : w.files) std::printf(" %s", f.c_str());
  std::printf("\n");
}

// Progress of a study: one line per point on a terminal, at most one every 10 s to a log. Called
// by the study's worker threads (under its lock); never throws.
std::function<void(const StudyProgress&)> study_printer(const StudyCommand& c) {
  if (c.quiet) return {};
  const bool every_line = c.progress || isatty(STDERR_FILENO);
  auto last = std::make_shared<std::chrono::steady_clock::time_point>();
  return [every_line, last](const StudyProgress& p) {
    const auto now = std::chrono::steady_clock::now();
    if (!every_line && p.done < p.total && now - *last < std::chrono::seconds(10)) return;
    *last = now;
    std::fprintf(stderr, "  [%zu/%zu] %zu failed, %.1f s elapsed, about %.0f s to go\n", p.done, p.total, p.failures,
                 p.elapsed_s, p.remaining_s);
  };
}

}  // namespace

int run_study_command(const StudyCommand& c) {
  const std::vector<std::string>& args = c.args;
  const std::string& shard_text = c.shard;
  const bool merge = args.front() == "merge";
  if (!merge && launched_by_mpirun() && !mpi_built()) {
    const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
    if (rank && std::string(rank) != "0") return 0;  // rank 0 runs the whole study
    std::fprintf(stderr, "lpshoot: launched under mpirun, but this lpshoot was built without MPI: rank 0 runs the "
                         "study locally on its threads (install libopenmpi-dev and rebuild, or use --shard)\n");
  }
  MpiSession world;  // MPI_Init under mpirun (MPI builds)
  if (merge && world.rank() > 0) return 0;
  StudyOutcome o;
  std::string out = c.out;
  try {
    if (merge) {
      if (out.empty()) return fail_input("study merge: --out: give the directory of the merged study");
      if (args.size() < 2) return fail_input("study merge: give the shard directories to merge");
      o = merge_studies({args.begin() + 1, args.end()}, out, c.plot);
      std::printf("merged %zu directories: %zu of %zu points\n", args.size() - 1, o.skipped, o.points);
    } else {
      if (args.size() > 1) return fail_input("study: one study file (got " + std::to_string(args.size()) + " arguments)");
      const Study st = load_study(args.front());
      StudyOptions so;
      so.out = out.empty() ? "lpshoot-out/" + st.name : out;
      out = so.out;
      so.threads = c.threads;
      so.plot = c.plot;
      if (!shard_text.empty()) {
        int i = -1, k = 0;
        char tail = 0;
        if (std::sscanf(shard_text.c_str(), "%d/%d%c", &i, &k, &tail) != 2 || k < 1 || i < 0 || i >= k)
          return fail_input("--shard: expected i/K with 0 <= i < K (got '" + shard_text + "')");
        so.shard = i, so.shards = k;
      }
      if (world.size() > 1 && world.rank() > 0) {  // a worker: rank 0 owns the directory and the report
        mpi_worker(st);
        return 0;
      }
      if (!c.quiet)
        std::fprintf(stderr, "lpshoot: study %s: %zu points%s into %s%s\n", st.file.c_str(), st.points(),
                   so.shards > 1 ? (" (shard " + shard_text + ")").c_str() : "", so.out.c_str(),
                   world.size() > 1 ? (", on " + std::to_string(world.size()) + " MPI ranks").c_str() : "");
      if (world.size() > 1) {
        bool ran = false;
        try {
          const auto notify = [&world](const std::string& what) {
            std::fprintf(stderr, "lpshoot: %s\n", what.c_str());
            world.abort_at_exit();  // MPI_Finalize would wait for the lost rank forever
          };
          o = run_study(st, so, study_printer(c), mpi_master_executor(world, c.rank_timeout_s, notify, &ran));
        } catch (...) {
          if (!ran) mpi_release_workers(world);
          throw;
        }
      } else {
        o = run_study(st, so, study_printer(c));
      }
      std::printf("study %s: %zu points, %zu run now, %zu done before, %zu not converged\n", st.file.c_str(), o.points,
                  o.run, o.skipped, o.failures);
    }
  } catch (const SceneError& e) {
    return world.rank() > 0 ? 2 : fail_input(e.what());  // every rank read the same file: rank 0 says why
  } catch (const OutputError& e) {
    std::fprintf(stderr, "lpshoot: cannot write the results: %s\n", e.what());
    return 3;
  } catch (const Interrupted& e) {
    std::fprintf(stderr, "lpshoot: %s; the points done are kept in %s/study.jsonl: run the study again to complete it\n",
                 e.what(), out.c_str());
    return 128 + e.signal;
  }
  print_files(o.written);
  if (o.failures > 0)
    std::fprintf(stderr, "lpshoot: %zu of %zu points failed: not converged, invalid or lost (their rows say why)\n", o.failures,
                 o.points);
  const int code = o.failures > 0 ? 1 : 0;
  world.set_exit_code(code);
  return code;
}

}  // namespace lpshoot::app
