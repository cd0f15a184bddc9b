// `lpshoot study` under mpirun (study_mpi.hpp). Messages: a rank sends rank 0 a row (JSON text),
// "" when it is ready for its first point, or "!" when it stops (interrupted); rank 0 answers a
// row or "" with a point index, or -1 for "stop".
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
  const int workers = world.size() - 1;
  return [workers, ran](const Study& study, const std::vector<size_t>& todo, const StudyRecorder& record,
                        const Progress& checkpoint) {
    *ran = true;
    size_t next = 0;
    int active = workers;  // ranks not yet told to stop (nor stopped by themselves)
    // Answers one message: records its row, hands out the next point or "stop".
    auto serve = [&](bool block) {
      auto [from, text] = receive(block);
      if (from < 0) return false;
      if (text == "!") {
        --active;
        return true;
      }
      if (!text.empty()) record(row_from_json(study, text));
      if (next < todo.size()) {
        send_index(static_cast<long long>(todo[next++]), from);
      } else {
        send_index(-1, from);
        --active;
      }
      return true;
    };
    try {
      while (next < todo.size()) {
        while (next < todo.size() && serve(false)) {
        }
        if (next < todo.size()) record(run_study_point(study, todo[next++], checkpoint));
      }
    } catch (...) {  // interrupted (or a row that does not parse): hand out nothing more, let every rank stop
      next = todo.size();
      while (active > 0) serve(true);
      throw;
    }
    while (active > 0) serve(true);
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
