// apps/prtr/mpi_world.h: the MPI job this prtr process is one rank of, if any
// (docs/ARCHITECTURE.md "Scale"). MPI is initialised only when the process was started by
// mpirun (Open MPI sets OMPI_COMM_WORLD_SIZE) and prtr was built with PRTR_MPI; otherwise
// the world is one rank and every call below is a no-op, so the commands need no #ifdefs.
#pragma once

#include "cpca/distribution.h"

#include <tbb/global_control.h>

#include <memory>
#include <string>

namespace prtr_app {

struct MpiWorld {
  int rank = 0, size = 1;
};

// Initialises MPI on first use (finalised at exit).
MpiWorld mpi_world();
bool mpi_built();

void mpi_barrier();
// The smallest `value` over all ranks.
int mpi_min(int value);
// The world as a cpca::Distribution, for a compression spread over the ranks. Its
// exchanges poll with short sleeps, like mpi_barrier, so a waiting rank leaves its core to
// the ranks still computing. Throws std::runtime_error without MPI.
std::unique_ptr<cpca::Distribution> mpi_distribution();

// Caps this process's TBB threads at its share of the node's cores (the cores over the ranks
// mpirun started on this node) while it lives: ranks that each start a thread per core
// oversubscribe the node and spin against each other. A no-op outside mpirun.
class MpiCoreShare {
 public:
  MpiCoreShare();
  ~MpiCoreShare();
  MpiCoreShare(const MpiCoreShare&) = delete;
  MpiCoreShare& operator=(const MpiCoreShare&) = delete;

 private:
  std::unique_ptr<tbb::global_control> control_;
};

// Prints "rank R: message" to stderr and ends the whole job with exit status 1, so that no
// rank waits forever for one that failed.
[[noreturn]] void mpi_abort(const std::string& message);

}  // namespace prtr_app
