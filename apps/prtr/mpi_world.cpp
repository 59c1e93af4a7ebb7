#include "mpi_world.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <thread>

#ifdef PRTR_HAVE_MPI
#include <mpi.h>
#endif

namespace prtr_app {

MpiCoreShare::MpiCoreShare() {
  const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  const int ranks = local ? std::atoi(local) : 1;
  if (ranks <= 1) return;
  const int cores = std::max(1, int(std::thread::hardware_concurrency()));
  control_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                   std::size_t(std::max(1, cores / ranks)));
}
MpiCoreShare::~MpiCoreShare() = default;

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

namespace {

// Waits for a nonblocking operation, sleeping between tests (MPI's blocking calls spin).
void wait(MPI_Request& request) {
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

int count_of(std::size_t bytes) {
  if (bytes > std::size_t(std::numeric_limits<int>::max()))
    throw std::runtime_error("an MPI message of " + std::to_string(bytes) +
                             " bytes exceeds 2 GiB: use more ranks");
  return int(bytes);
}

class MpiDistribution final : public cpca::Distribution {
 public:
  int rank() const override { return mpi_world().rank; }
  int size() const override { return mpi_world().size; }
  void chain_receive(void* data, std::size_t bytes) override {
    MPI_Request r{};
    MPI_Irecv(data, count_of(bytes), MPI_BYTE, rank() - 1, kChainTag, MPI_COMM_WORLD, &r);
    wait(r);
  }
  void chain_send(const void* data, std::size_t bytes) override {
    MPI_Request r{};
    MPI_Isend(data, count_of(bytes), MPI_BYTE, rank() + 1, kChainTag, MPI_COMM_WORLD, &r);
    wait(r);
  }
  void broadcast(void* data, std::size_t bytes, int root) override {
    MPI_Request r{};
    MPI_Ibcast(data, count_of(bytes), MPI_BYTE, root, MPI_COMM_WORLD, &r);
    wait(r);
  }
  std::vector<unsigned char> gather(const void* data, std::size_t bytes, int root) override {
    const int mine = count_of(bytes);
    const std::size_t ranks = std::size_t(size());
    std::vector<int> counts(ranks, 0), offsets(ranks, 0);
    MPI_Request r{};
    MPI_Igather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, root, MPI_COMM_WORLD, &r);
    wait(r);
    std::size_t total = 0;
    for (std::size_t i = 0; i < counts.size(); ++i) {
      offsets[i] = count_of(total);
      total += std::size_t(counts[i]);
    }
    std::vector<unsigned char> out(rank() == root ? total : 0);
    MPI_Igatherv(data, mine, MPI_BYTE, out.data(), counts.data(), offsets.data(), MPI_BYTE, root,
                 MPI_COMM_WORLD, &r);
    wait(r);
    return out;
  }

 private:
  static constexpr int kChainTag = 17;
};

}  // namespace

std::unique_ptr<cpca::Distribution> mpi_distribution() {
  return std::make_unique<MpiDistribution>();
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
std::unique_ptr<cpca::Distribution> mpi_distribution() {
  throw std::runtime_error("prtr was built without MPI");
}
void mpi_abort(const std::string& message) {
  std::fprintf(stderr, "prtr: %s\n", message.c_str());
  std::exit(1);
}

#endif

}  // namespace prtr_app
