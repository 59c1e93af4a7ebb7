// cpca/distribution.h: the processes one compression is spread over (docs/ARCHITECTURE.md
// "Scale"). cpca knows nothing of MPI: a distributed run passes an implementation of this
// interface (prtr's lives in apps/prtr/mpi_world.h), a single process passes SingleProcess,
// for which every exchange is a no-op. Every rank sees all rows (each maps the whole .prtx)
// and owns a contiguous range of them (rank_rows).
//
// Reductions that must be bit-identical to one process cannot use an allreduce, whose order
// is the library's: they run as a chain instead. Rank r receives rank r-1's running state,
// continues it over its own rows in order, and sends it to rank r+1; the last rank's result is
// broadcast. The additions then happen in exactly the single-process order.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace cpca {

class Distribution {
 public:
  virtual ~Distribution() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Point to point along the chain: receive from rank - 1 (never called on rank 0), send to
  // rank + 1 (never called on the last rank). Both sides agree on the byte count.
  virtual void chain_receive(void* data, std::size_t bytes) = 0;
  virtual void chain_send(const void* data, std::size_t bytes) = 0;
  // `root`'s bytes to every rank.
  virtual void broadcast(void* data, std::size_t bytes, int root) = 0;
  // Every rank's bytes (sizes may differ), concatenated in rank order, on `root`; an empty
  // vector elsewhere.
  virtual std::vector<unsigned char> gather(const void* data, std::size_t bytes, int root) = 0;

  bool first() const { return rank() == 0; }
  bool last() const { return rank() == size() - 1; }
};

// One process: rank 0 of 1; nothing to exchange.
class SingleProcess final : public Distribution {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void chain_receive(void*, std::size_t) override {}
  void chain_send(const void*, std::size_t) override {}
  void broadcast(void*, std::size_t, int) override {}
  std::vector<unsigned char> gather(const void* data, std::size_t bytes, int) override;
};

struct RowRange {
  Eigen::Index begin = 0, end = 0;
  Eigen::Index size() const { return end - begin; }
};

// The rows `rank` of `size` owns: contiguous, in rank order, boundaries on multiples of
// `granule` (RowBlocks::kGranule, so every distance product sees the rows it sees in one
// process). Ranks past the data get an empty range.
RowRange rank_rows(Eigen::Index rows, int rank, int size, Eigen::Index granule);

// The chain above over `state`: receive (rank > 0), continue(state), send (not last), then
// the last rank's state is broadcast to all.
template <class T, class F>
void chain(Distribution& d, std::vector<T>& state, F&& continue_with_mine) {
  const std::size_t bytes = state.size() * sizeof(T);
  if (!d.first()) d.chain_receive(state.data(), bytes);
  continue_with_mine(state);
  if (!d.last()) d.chain_send(state.data(), bytes);
  d.broadcast(state.data(), bytes, d.size() - 1);
}

// Each rank's `mine` (its rank_rows slice of `all`) into `all` on every rank.
template <class T>
void all_gather_rows(Distribution& d, std::vector<T>& all, RowRange mine) {
  if (d.size() == 1) return;
  const std::vector<unsigned char> joined =
      d.gather(all.data() + mine.begin, std::size_t(mine.size()) * sizeof(T), 0);
  if (d.first())
    std::copy(joined.begin(), joined.end(), reinterpret_cast<unsigned char*>(all.data()));
  d.broadcast(all.data(), all.size() * sizeof(T), 0);
}

}  // namespace cpca
