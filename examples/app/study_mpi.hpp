// `lpshoot study` under mpirun (study_mpi.cpp when CMake finds MPI; study_no_mpi.cpp otherwise).
// Rank 0 owns the study's directory and hands out points to the ranks as they return rows,
// solving points itself on a second thread; the other ranks solve what they are given.
// Linked into the lpshoot executable only: the library and plugins never see MPI.
#pragma once

#include "study_run.hpp"

namespace lpshoot::app {

// Started by mpirun (its environment), whether or not this lpshoot was built with MPI.
bool launched_by_mpirun();
bool mpi_built();

// Joins the MPI world while alive when launched by mpirun (MPI_Init / MPI_Finalize); a world of
// one rank otherwise.
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int size() const { return size_; }
  int rank() const { return rank_; }
  // A rank was lost: end the job with MPI_Abort(exit code) instead of MPI_Finalize, whose
  // collective shutdown would wait for the lost rank forever (the study's files are complete).
  void abort_at_exit() { abort_ = true; }
  void set_exit_code(int code) { exit_code_ = code; }

 private:
  int size_ = 1, rank_ = 0, exit_code_ = 0;
  bool joined_ = false, abort_ = false;
};

// Rank 0's executor for run_study: every rank 1.. is told to stop by the time it returns or
// throws. A rank silent for rank_timeout_s while it holds points (or before its first) is lost:
// `notify` is told, and its points become rows with status rank_lost. `ran` is set when it starts.
StudyExecutor mpi_master_executor(const MpiSession& world, double rank_timeout_s,
                                  const std::function<void(const std::string&)>& notify, bool* ran);
// Rank 0, when it stops before its executor ran (a bad directory): tells the ranks to stop.
void mpi_release_workers(const MpiSession& world);
// Ranks 1..: solve the points rank 0 hands out until it says stop.
void mpi_worker(const Study& study);

}  // namespace lpshoot::app
