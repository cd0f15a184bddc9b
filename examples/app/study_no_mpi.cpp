// `lpshoot study` in a build without MPI (study_mpi.hpp): a world of one rank. Launched by mpirun,
// rank 0 runs the study locally and says so; the other ranks leave it to rank 0 (main.cpp).
#include "study_mpi.hpp"

#include <cstdlib>
#include <stdexcept>

namespace lpshoot::app {

bool launched_by_mpirun() { return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE"); }
bool mpi_built() { return false; }
MpiSession::MpiSession() = default;
MpiSession::~MpiSession() = default;
StudyExecutor mpi_master_executor(const MpiSession&, double, const std::function<void(const std::string&)>&, bool*) { throw std::logic_error("lpshoot was built without MPI"); }
void mpi_release_workers(const MpiSession&) {}
void mpi_worker(const Study&) { throw std::logic_error("lpshoot was built without MPI"); }

}  // namespace lpshoot::app
