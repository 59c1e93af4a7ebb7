#include "mpi_world.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>

#ifdef PRTR_HAVE_MPI
#include <mpi.h>
#endif

namespace prtr_app {

#ifdef PRTR_HAVE_MPI

namespace {
void finalize() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}
}  // namespace

MpiWorld mpi_world() {
  static const MpiWorld world = [] {
    MpiWorld w;
    if (!std::getenv("OMPI_COMM_WORLD_SIZE")) return w;
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    std::atexit(finalize);
    MPI_Comm_rank(MPI_COMM_WORLD, &w.rank);
    MPI_Comm_size(MPI_COMM_WORLD, &w.size);
    return w;
  }();
  return world;
}

bool mpi_built() {
  return true;
}

void mpi_barrier() {
  if (mpi_world().size == 1) return;
  // Polled with sleeps: MPI_Barrier spins, and a rank that finished its shard early would
  // take a core from the ranks still baking on the same node.
  MPI_Request request{};
  MPI_Ibarrier(MPI_COMM_WORLD, &request);
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

int mpi_min(int value) {
  if (mpi_world().size == 1) return value;
  int out = value;
  MPI_Allreduce(&value, &out, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return out;
}

void mpi_abort(const std::string& message) {
  std::fprintf(stderr, "prtr: rank %d of %d: %s\n", mpi_world().rank, mpi_world().size,
               message.c_str());
  std::fflush(stderr);
  if (mpi_world().size > 1) MPI_Abort(MPI_COMM_WORLD, 1);
  std::exit(1);
}

#else

MpiWorld mpi_world() {
  return {};
}
bool mpi_built() {
  return false;
}
void mpi_barrier() {}
int mpi_min(int value) {
  return value;
}
void mpi_abort(const std::string& message) {
  std::fprintf(stderr, "prtr: %s\n", message.c_str());
  std::exit(1);
}

#endif

}  // namespace prtr_app
