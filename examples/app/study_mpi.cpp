// `lpshoot study` under mpirun (study_mpi.hpp). Messages: a rank sends rank 0 a row (JSON text),
// "" when it is ready for its first points, or "!" when it stops (interrupted); rank 0 sends a
// rank point indices (two ahead, then one per row returned), and -1 after its last one: "stop".
#include "study_mpi.hpp"

#include "interrupt.hpp"

#include <mpi.h>

#include <cstdlib>

namespace lpshoot::app {
namespace {

constexpr int to_master = 1, to_worker = 2;

void send_text(const std::string& s, int to, int tag) {
  MPI_Send(s.data(), static_cast<int>(s.size()), MPI_CHAR, to, tag, MPI_COMM_WORLD);
}

// The next message to rank 0: (its source, its text); blocking or not (source -1: none).
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

}  // namespace

bool launched_by_mpirun() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE"); }
bool mpi_built() { return true; }

MpiSession::MpiSession() {
  if (!launched_by_mpirun()) return;
  MPI_Init(nullptr, nullptr);
  joined_ = true;
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
}

MpiSession::~MpiSession() {
  if (joined_) MPI_Finalize();
}

StudyExecutor mpi_master_executor(const MpiSession& world, bool* ran) {
  const int size = world.size();
  return [size, ran](const Study& study, const std::vector<size_t>& todo, const StudyRecorder& record,
                     const Progress& checkpoint) {
    *ran = true;
    // Every rank holds one point in hand beyond the one it solves, so it never waits for rank 0
    // (which answers between its own points): two points on "ready", one more per row returned.
    constexpr int ahead = 2;
    size_t next = 0;
    std::vector<int> pending(static_cast<size_t>(size), 0);  // points handed out, rows not yet back
    std::vector<bool> stopped(static_cast<size_t>(size), false);
    stopped[0] = true;
    auto busy = [&] {
      for (int w = 1; w < size; ++w)
        if (!stopped[static_cast<size_t>(w)] || pending[static_cast<size_t>(w)] > 0) return true;
      return false;
    };
    auto hand_out = [&](int to, int count) {
      for (int k = 0; k < count && next < todo.size(); ++k, ++pending[static_cast<size_t>(to)])
        send_index(static_cast<long long>(todo[next++]), to);
      if (next >= todo.size() && !stopped[static_cast<size_t>(to)]) {  // after its last point, it stops
        send_index(-1, to);
        stopped[static_cast<size_t>(to)] = true;
      }
    };
    // Answers one message: records its row, hands out what the rank needs next.
    auto serve = [&](bool block) {
      auto [from, text] = receive(block);
      if (from < 0) return false;
      const size_t w = static_cast<size_t>(from);
      if (text == "!") {  // interrupted: it stops, its points in hand are not done
        stopped[w] = true;
        pending[w] = 0;
      } else if (text.empty()) {
        hand_out(from, ahead);
      } else {
        --pending[w];
        record(row_from_json(study, text));
        hand_out(from, 1);
      }
      return true;
    };
    try {
      while (next < todo.size()) {
        while (next < todo.size() && serve(false)) {
        }
        if (next < todo.size()) record(run_study_point(study, todo[next++], checkpoint));
      }
      for (int w = 1; w < size; ++w)  // ranks still waiting with nothing more to do
        if (!stopped[static_cast<size_t>(w)] && pending[static_cast<size_t>(w)] > 0) hand_out(w, 0);
    } catch (...) {  // interrupted (or a row that does not parse): hand out nothing more, let every rank stop
      next = todo.size();
      while (busy()) serve(true);
      throw;
    }
    while (busy()) serve(true);
  };
}

void mpi_release_workers(const MpiSession& world) {
  for (int k = 1; k < world.size(); ++k) {
    const auto [from, text] = receive(true);
    if (text != "!") send_index(-1, from);
  }
}

void mpi_worker(const Study& study) {
  const Progress checkpoint = [](const std::string&) { throw_if_interrupted(); };
  std::string message;  // first: ready
  for (;;) {
    send_text(message, 0, to_master);
    long long index = -1;
    MPI_Recv(&index, 1, MPI_LONG_LONG, 0, to_worker, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (index < 0) return;
    try {
      message = row_json(study, run_study_point(study, static_cast<size_t>(index), checkpoint));
    } catch (const Interrupted&) {
      send_text("!", 0, to_master);
      return;
    }
  }
}

}  // namespace lpshoot::app
