// Compression spread over ranks (cpca/distribution.h) against the one-process calls, bit for
// bit. The ranks are threads of this process exchanging through in-memory mailboxes, so the
// chained reductions, broadcasts and gathers run exactly as under MPI without mpirun.
#include "cpca/distribution.h"
#include "cpca/compress.h"
#include "cpca/lbg.h"
#include "cpca/row_blocks.h"

#include <gtest/gtest.h>

#include <condition_variable>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <thread>
#include <utility>
#include <vector>

namespace {

using Bytes = std::vector<unsigned char>;

// FIFO queues per (sender, receiver): every rank issues its exchanges in the same program
// order, so each pair's messages arrive in the order they are expected.
class Mailboxes {
 public:
  void send(int from, int to, const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      queues_[{from, to}].emplace_back(p, p + bytes);
    }
    ready_.notify_all();
  }
  Bytes receive(int from, int to) {
    std::unique_lock<std::mutex> lock(mutex_);
    auto& q = queues_[{from, to}];
    ready_.wait(lock, [&] { return !q.empty(); });
    Bytes out = std::move(q.front());
    q.pop_front();
    return out;
  }

 private:
  std::mutex mutex_;
  std::condition_variable ready_;
  std::map<std::pair<int, int>, std::deque<Bytes>> queues_;
};

class ThreadRank final : public cpca::Distribution {
 public:
  ThreadRank(int rank, int size, Mailboxes& box) : rank_(rank), size_(size), box_(box) {}
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void chain_receive(void* data, std::size_t bytes) override { take(rank_ - 1, data, bytes); }
  void chain_send(const void* data, std::size_t bytes) override {
    box_.send(rank_, rank_ + 1, data, bytes);
  }
  void broadcast(void* data, std::size_t bytes, int root) override {
    if (rank_ != root) return take(root, data, bytes);
    for (int r = 0; r < size_; ++r)
      if (r != root) box_.send(root, r, data, bytes);
  }
  Bytes gather(const void* data, std::size_t bytes, int root) override {
    if (rank_ != root) {
      box_.send(rank_, root, data, bytes);
      return {};
    }
    Bytes out;
    for (int r = 0; r < size_; ++r) {
      const Bytes part = r == root ? Bytes(static_cast<const unsigned char*>(data),
                                           static_cast<const unsigned char*>(data) + bytes)
                                   : box_.receive(r, root);
      out.insert(out.end(), part.begin(), part.end());
    }
    return out;
  }

 private:
  void take(int from, void* data, std::size_t bytes) {
    const Bytes b = box_.receive(from, rank_);
    ASSERT_EQ(b.size(), bytes);
    std::memcpy(data, b.data(), bytes);
  }
  int rank_, size_;
  Mailboxes& box_;
};

// f(distribution) on `ranks` threads; returns each rank's result.
template <class F>
auto run_ranks(int ranks, F f) {
  using Result = decltype(f(std::declval<cpca::Distribution&>()));
  Mailboxes box;
  // One object per rank: a std::vector<bool> packs the ranks' results into shared words, so
  // two threads writing theirs would race.
  std::vector<std::optional<Result>> slots(static_cast<std::size_t>(ranks));
  std::vector<std::thread> threads;
  for (int r = 0; r < ranks; ++r)
    threads.emplace_back([&, r] {
      ThreadRank rank(r, ranks, box);
      slots[std::size_t(r)] = f(rank);
    });
  for (auto& t : threads) t.join();
  std::vector<Result> out;
  for (auto& slot : slots) out.push_back(std::move(*slot));
  return out;
}

// Clustered rows and far outliers, so that null clusters appear and get split.
cpca::DataMatrix clustered(Eigen::Index rows, Eigen::Index cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, 0.3f);
  std::uniform_int_distribution<int> centre(0, 5);
  cpca::DataMatrix x(rows, cols);
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index j = 0; j < cols; ++j)
      x(i, j) = float(centre(rng) * (j % 3 + 1)) + noise(rng) * float(1 + i % 7);
  // A few far rows stretch the hyper box, so many initial means land where no row is.
  for (Eigen::Index i = 0; i < rows; i += 97) x.row(i).setConstant(60.f);
  return x;
}

// Compression of clustered()'s 9-column rows (order 3, one channel, one row per vertex).
cpca::CompressOptions small_compression(int clusters, int components) {
  cpca::CompressOptions options;
  options.layout = {3, 1, 1};
  options.clusters = clusters;
  options.components = components;
  return options;
}

TEST(Distribution, RankRowsAreContiguousOnTheGranuleAndCoverEveryRow) {
  for (Eigen::Index rows : {1, 255, 256, 1000, 5000})
    for (int size : {1, 2, 3, 7}) {
      Eigen::Index next = 0;
      for (int r = 0; r < size; ++r) {
        const cpca::RowRange range = cpca::rank_rows(rows, r, size, 256);
        EXPECT_EQ(range.begin, next);
        EXPECT_LE(range.begin, range.end);
        if (range.end != rows) {
          EXPECT_EQ(range.end % 256, 0);
        }
        next = range.end;
      }
      EXPECT_EQ(next, rows);
    }
}

// Cluster 0's sum cancels: 1e16 at row 0 (rank 0), where double keeps only even integers,
// so each later member's value is rounded into the sum, and -1e16 at its last member (last
// rank). The mean is the rounding left over, which depends on the order of the additions:
// only the chain reproduces it; summing each rank's rows from zero and adding the partial
// sums (an allreduce) does not.
TEST(Distribution, ChainedMeansAndEnergyEqualOneProcessBitForBit) {
  const Eigen::Index rows = 1500;
  cpca::DataMatrix x = clustered(rows, 5, 3);
  std::vector<std::uint32_t> ids(static_cast<std::size_t>(rows));
  for (Eigen::Index i = 0; i < rows; ++i) ids[std::size_t(i)] = std::uint32_t(i % 4);
  x(0, 0) = 1e16f;
  x(rows - 4, 0) = -1e16f;
  const cpca::RowBlocks blocks(x, 256);
  const cpca::DataMatrix means = cpca::cluster_means(blocks, ids, 4);
  const double energy = cpca::clustering_energy(blocks, ids, means);
  for (int ranks : {2, 3, 5}) {
    const auto got = run_ranks(ranks, [&](cpca::Distribution& d) {
      const cpca::DataMatrix m = cpca::cluster_means(blocks, ids, 4, d);
      return std::make_pair(m, cpca::clustering_energy(blocks, ids, m, d));
    });
    for (const auto& [m, e] : got) {
      EXPECT_TRUE(m == means) << ranks << " ranks";
      EXPECT_EQ(e, energy) << ranks << " ranks";
    }
  }
}

TEST(Distribution, LbgOverRanksEqualsOneProcessBitForBit) {
  const cpca::DataMatrix x = clustered(1300, 6, 7);
  cpca::LbgOptions options;
  options.clusters = 24;
  options.seed = 5;
  const cpca::LbgResult one = cpca::lbg(cpca::RowBlocks(x, 256), options);
  ASSERT_GT(one.splits, 0) << "the data should exercise the null-cluster split";
  ASSERT_GT(one.iterations, 2);
  for (int ranks : {2, 3, 6}) {
    const auto got = run_ranks(ranks, [&](cpca::Distribution& d) {
      return cpca::lbg(cpca::RowBlocks(x, 256), options, d);
    });
    for (const cpca::LbgResult& r : got) {
      EXPECT_EQ(r.cluster_of, one.cluster_of) << ranks << " ranks";
      EXPECT_TRUE(r.means == one.means) << ranks << " ranks";
      EXPECT_EQ(r.energy, one.energy) << ranks << " ranks";
      EXPECT_EQ(r.splits, one.splits);
    }
  }
}

TEST(Distribution, CompressOverRanksGivesRankZeroTheOneProcessSet) {
  const cpca::DataMatrix x = clustered(1100, 9, 11);
  const cpca::CompressOptions options = small_compression(20, 3);
  cpca::CompressReport one_report;
  const cpca::CompressedSet one = cpca::compress(cpca::RowBlocks(x), options, nullptr, &one_report);
  for (int ranks : {2, 3}) {
    const auto got = run_ranks(ranks, [&](cpca::Distribution& d) {
      cpca::CompressReport report;
      cpca::CompressedSet set =
          cpca::compress(cpca::RowBlocks(x, 256), options, nullptr, &report, {}, &d);
      return std::make_pair(set, report);
    });
    const auto& [set, report] = got.front();
    EXPECT_EQ(set.cluster_of, one.cluster_of);
    EXPECT_EQ(set.means, one.means);
    EXPECT_EQ(set.bases, one.bases);
    EXPECT_EQ(set.weights, one.weights);
    EXPECT_EQ(report.error.average_squared_error, one_report.error.average_squared_error);
    EXPECT_EQ(report.power_iterations, one_report.power_iterations);
  }
}

TEST(Distribution, MethodsWithoutAChainedFormAreRefused) {
  const cpca::DataMatrix x = clustered(600, 9, 1);
  cpca::CompressOptions options = small_compression(8, 2);
  options.method = cpca::ClusterMethod::kIterative;
  const auto refused = run_ranks(2, [&](cpca::Distribution& d) {
    try {
      cpca::compress(cpca::RowBlocks(x), options, nullptr, nullptr, {}, &d);
    } catch (const std::invalid_argument&) {
      return true;
    }
    return false;
  });
  EXPECT_EQ(refused, (std::vector<bool>{true, true}));
}

}  // namespace
