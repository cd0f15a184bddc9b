// `lpshoot study` under mpirun (study_mpi.hpp).
//
// Messages to rank 0: a row (JSON text), "" (ready for its first points), "." (a heartbeat, sent
// from the solver's checkpoints at most once a second), "!" (the rank stops: interrupted). Rank 0
// sends a rank point indices — two ahead, then one per row returned, so that a rank never waits
// — and -1 after the last: "stop". Rank 0's own points run on a second thread; its main thread
// only serves messages (MPI_THREAD_FUNNELED) and watches the ranks: one silent for longer than
// the timeout while it holds points is lost, and its points become rows with status rank_lost
// (mpirun --enable-recovery keeps the other ranks alive when one dies).
#include "study_mpi.hpp"

#include "interrupt.hpp"

#include <mpi.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <thread>

namespace lpshoot::app {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int to_master = 1, to_worker = 2;

void send_text(const std::string& s, int to, int tag) {
  MPI_Send(s.data(), static_cast<int>(s.size()), MPI_CHAR, to, tag, MPI_COMM_WORLD);
}

// The next message to rank 0, if one is there: (its source, its text); source -1: none.
std::pair<int, std::string> receive(bool block) {
  MPI_Status st;
  int flag = 1;
  if (block) MPI_Probe(MPI_ANY_SOURCE, to_master, MPI_COMM_WORLD, &st);
  else MPI_Iprobe(MPI_ANY_SOURCE, to_master, MPI_COMM_WORLD, &flag, &st);
  if (!flag) return {-1, ""};
  int n = 0;
  MPI_Get_count(&st, MPI_CHAR, &n);
  std::string text(static_cast<size_t>(n), '\0');
  MPI_Recv(text.data(), n, MPI_CHAR, st.MPI_SOURCE, to_master, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return {st.MPI_SOURCE, text};
}

void send_index(long long index, int to) { MPI_Send(&index, 1, MPI_LONG_LONG, to, to_worker, MPI_COMM_WORLD); }

struct Rank {
  std::deque<size_t> in_hand;  // points handed out whose rows are not back, in order
  bool stopped = false;        // told to stop, stopped by itself, or lost
  Clock::time_point last_heard = Clock::now();
};

}  // namespace

bool launched_by_mpirun() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE"); }
bool mpi_built() { return true; }

MpiSession::MpiSession() {
  if (!launched_by_mpirun()) return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  joined_ = true;
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);  // a send to a lost rank does not abort
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
}

MpiSession::~MpiSession() {
  if (!joined_) return;
  if (abort_) {
    std::fflush(nullptr);
    MPI_Abort(MPI_COMM_WORLD, exit_code_);
  }
  MPI_Finalize();
}

StudyExecutor mpi_master_executor(const MpiSession& world, double rank_timeout_s, const std::function<void(const std::string&)>& notify,
                                  bool* ran) {
  const int size = world.size();
  return [size, rank_timeout_s, notify, ran](const Study& study, const std::vector<size_t>& todo,
                                             const StudyRecorder& record, const Progress& checkpoint) {
    *ran = true;
    constexpr size_t ahead = 2;
    std::mutex m;  // guards `next` (rank 0's solver thread takes points too)
    size_t next = 0;
    auto take = [&]() -> long long {
      const std::lock_guard<std::mutex> lock(m);
      return next < todo.size() ? static_cast<long long>(todo[next++]) : -1;
    };
    auto exhausted = [&] {
      const std::lock_guard<std::mutex> lock(m);
      return next >= todo.size();
    };
    auto give_up = [&] {
      const std::lock_guard<std::mutex> lock(m);
      next = todo.size();
    };

    // Rank 0's own points, on a thread of their own (no MPI calls there).
    std::atomic<bool> local_done{false}, interrupted{false};
    std::thread local([&] {
      try {
        for (long long i; (i = take()) >= 0;) record(run_study_point(study, static_cast<size_t>(i), checkpoint));
      } catch (const Interrupted&) {
        interrupted = true;
      }
      local_done = true;
    });

    std::vector<Rank> ranks(static_cast<size_t>(size));
    ranks[0].stopped = true;
    auto hand_out = [&](int to, size_t count) {
      Rank& r = ranks[static_cast<size_t>(to)];
      for (size_t k = 0; k < count; ++k) {
        const long long i = take();
        if (i < 0) break;
        send_index(i, to);
        r.in_hand.push_back(static_cast<size_t>(i));
      }
      if (exhausted() && !r.stopped) {  // after its points in hand, it stops
        send_index(-1, to);
        r.stopped = true;
      }
    };
    auto busy = [&] {
      for (size_t w = 1; w < ranks.size(); ++w)
        if (!ranks[w].stopped || !ranks[w].in_hand.empty()) return true;
      return !local_done;
    };
    auto lose = [&](size_t w, const std::string& why) {
      Rank& r = ranks[w];
      if (notify)
        notify("rank " + std::to_string(w) + " " + why + ": its " + std::to_string(r.in_hand.size()) +
               " point(s) in hand are marked rank_lost (rerunning the study solves them)");
      for (size_t i : r.in_hand) {
        StudyRow row;
        row.index = i;
        row.values = study.point(i);
        row.status = "rank_lost";
        row.message = "MPI rank " + std::to_string(w) + " " + why + " while holding this point";
        record(std::move(row));
      }
      r.in_hand.clear();
      r.stopped = true;
    };

    while (busy()) {
      if (interrupted || interrupt_signal()) give_up();  // hand out nothing more; let every rank finish
      auto [from, text] = receive(false);
      if (from < 0) {
        const auto now = Clock::now();
        for (size_t w = 1; w < ranks.size(); ++w)  // holding points, or not yet ready
          if ((!ranks[w].stopped || !ranks[w].in_hand.empty()) &&
              now - ranks[w].last_heard > std::chrono::duration<double>(rank_timeout_s))
            lose(w, "stopped answering (no message for " + std::to_string(static_cast<int>(rank_timeout_s)) +
                        " s: it died or hangs)");
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      Rank& r = ranks[static_cast<size_t>(from)];
      r.last_heard = Clock::now();
      if (text == ".") continue;  // a heartbeat
      if (text == "!") {          // interrupted: it stops; its points in hand are not done
        r.in_hand.clear();
        r.stopped = true;
        continue;
      }
      if (text.empty()) {
        hand_out(from, ahead);
        continue;
      }
      StudyRow row = row_from_json(study, text);
      for (auto it = r.in_hand.begin(); it != r.in_hand.end(); ++it)
        if (*it == row.index) {
          r.in_hand.erase(it);
          break;
        }
      record(std::move(row));
      hand_out(from, 1);
    }
    local.join();
    if (interrupted || interrupt_signal()) throw Interrupted(interrupt_signal() ? interrupt_signal() : 2);
  };
}

void mpi_release_workers(const MpiSession& world) {
  for (int k = 1; k < world.size(); ++k) {
    auto [from, text] = receive(true);
    while (text == ".") std::tie(from, text) = receive(true);
    if (text != "!") send_index(-1, from);
  }
}

void mpi_worker(const Study& study) {
  auto last_beat = std::make_shared<Clock::time_point>(Clock::now());
  const Progress checkpoint = [last_beat](const std::string&) {
    throw_if_interrupted();
    if (Clock::now() - *last_beat > std::chrono::seconds(1)) {  // alive, still solving
      send_text(".", 0, to_master);
      *last_beat = Clock::now();
    }
  };
  std::string message;  // first: ready
  for (;;) {
    send_text(message, 0, to_master);
    long long index = -1;
    MPI_Recv(&index, 1, MPI_LONG_LONG, 0, to_worker, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (index < 0) return;
    *last_beat = Clock::now();
    try {
      message = row_json(study, run_study_point(study, static_cast<size_t>(index), checkpoint));
    } catch (const Interrupted&) {
      send_text("!", 0, to_master);
      return;
    }
  }
}

}  // namespace lpshoot::app
