// Out-of-core compression (cpca/row_blocks.h): LBG, the PCA per cluster and the whole
// compression streamed over tiny blocks equal the in-memory ones bit for bit, and the
// streamed LBG equals an independent whole-matrix LBG (the algorithm of thesis Fig. 3.2 as
// the in-memory code ran it before streaming: V x K distances, members gathered per cluster).
#include "cpca/assignment.h"
#include "cpca/cluster_pca.h"
#include "cpca/compress.h"
#include "cpca/lbg.h"
#include "cpca/row_blocks.h"

#include "cpca_test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

namespace {

constexpr int kSide = 39;       // a 39 x 39 grid: 1521 rows
constexpr int kDimension = 25;  // diffuse grey order 5
constexpr cpca::DataLayout kLayout{5, 1, 1};

// Rows near a few smooth functions of position, so clusters and PCs have structure.
cpca::DataMatrix grid_data(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, 0.05f);
  cpca::DataMatrix x(kSide * kSide, kDimension);
  for (int p = 0; p < x.rows(); ++p) {
    const float u = float(p % kSide) / kSide, v = float(p / kSide) / kSide;
    for (int d = 0; d < kDimension; ++d)
      x(p, d) =
          std::sin(3.f * u * float(d % 5 + 1)) * std::cos(2.f * v * float(d / 5 + 1)) + noise(rng);
  }
  return x;
}

// Records every release, so a test can see the passes really went block by block.
struct Releases {
  std::vector<std::pair<Eigen::Index, Eigen::Index>> calls;
  cpca::RowBlocks::Release hook() {
    return [this](Eigen::Index first, Eigen::Index rows) { calls.emplace_back(first, rows); };
  }
  Eigen::Index largest_partial(Eigen::Index all) const {
    Eigen::Index largest = 0;
    for (const auto& [first, rows] : calls)
      if (!(first == 0 && rows == all)) largest = std::max(largest, rows);
    return largest;
  }
};

double next_uniform(std::uint64_t& state) {  // splitmix64, as cpca seeds its starts
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return double(z >> 11) * 0x1.0p-53;
}

cpca::LbgResult whole_matrix_lbg(const cpca::DataMatrix& x, const cpca::LbgOptions& o) {
  const int k = o.clusters;
  const Eigen::VectorXf norms = x.rowwise().squaredNorm();
  const Eigen::RowVectorXf lo = x.colwise().minCoeff(), hi = x.colwise().maxCoeff();
  cpca::LbgResult r;
  r.means.resize(k, x.cols());
  std::uint64_t state = o.seed;
  for (int j = 0; j < k; ++j)
    for (Eigen::Index d = 0; d < x.cols(); ++d)
      r.means(j, d) = lo[d] + float(next_uniform(state)) * (hi[d] - lo[d]);
  double previous = 0;
  for (int it = 1; it <= o.max_iterations; ++it) {
    r.cluster_of = cpca::argmin_rows(cpca::squared_distances(x, norms, r.means));
    r.splits += cpca::split_empty_clusters(x, r.cluster_of, k);
    const auto members = cpca::cluster_members(r.cluster_of, k);
    r.means.setZero();
    for (int j = 0; j < k; ++j) {
      Eigen::RowVectorXd sum = Eigen::RowVectorXd::Zero(x.cols());
      for (std::uint32_t p : members[std::size_t(j)]) sum += x.row(p).cast<double>();
      r.means.row(j) = (sum / double(members[std::size_t(j)].size())).cast<float>();
    }
    double energy = 0;  // per 1024-row chunk, then the chunks in order
    for (Eigen::Index c = 0; c < x.rows(); c += 1024) {
      double chunk = 0;
      for (Eigen::Index p = c; p < std::min(x.rows(), c + 1024); ++p)
        chunk +=
            (x.row(p) - r.means.row(r.cluster_of[std::size_t(p)])).cast<double>().squaredNorm();
      energy += chunk;
    }
    r.energy.push_back(energy);
    r.iterations = it;
    const double ratio = it == 1 ? 1.0 : (previous - energy) / previous;
    if (energy == 0.0 || (it > 1 && std::abs(ratio) < o.threshold)) break;
    previous = energy;
  }
  return r;
}

void expect_same(const cpca::LbgResult& a, const cpca::LbgResult& b) {
  EXPECT_EQ(a.cluster_of, b.cluster_of);
  EXPECT_TRUE(a.means == b.means);
  EXPECT_EQ(a.energy, b.energy);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.splits, b.splits);
}

TEST(OutOfCore, LbgOverTinyBlocksEqualsTheWholeMatrixLbg) {
  const cpca::DataMatrix x = grid_data(1);
  for (int k : {1, 13, 64}) {
    cpca::LbgOptions o;
    o.clusters = k;
    o.seed = 7;
    o.threshold = 1e-4;
    const cpca::LbgResult oracle = whole_matrix_lbg(x, o);
    ASSERT_GT(oracle.iterations, 1);
    expect_same(cpca::lbg(x, o), oracle);
    for (Eigen::Index block : {1, 300, 5000}) {
      SCOPED_TRACE("k " + std::to_string(k) + ", block " + std::to_string(block));
      Releases releases;
      const cpca::RowBlocks blocks(x, block, releases.hook());
      expect_same(cpca::lbg(blocks, o), oracle);
      EXPECT_LE(releases.largest_partial(x.rows()), std::max<Eigen::Index>(block, 256) + 255);
      if (block < x.rows()) {
        EXPECT_GT(releases.largest_partial(x.rows()), 0);
      }
    }
  }
}

TEST(OutOfCore, NullClustersAreSplitTheSameWay) {
  cpca::DataMatrix x = grid_data(2);
  x.bottomRows(600) = x.topRows(1).replicate(600, 1);  // duplicates provoke empty clusters
  cpca::LbgOptions o;
  o.clusters = 40;
  const cpca::LbgResult oracle = whole_matrix_lbg(x, o);
  ASSERT_GT(oracle.splits, 0);
  expect_same(cpca::lbg(cpca::RowBlocks(x, 1), o), oracle);
}

// Rows whose view is all zeros and whose gather() serves `x`: whatever reads the view
// instead of gathering sees zeros and gets a different result.
cpca::RowBlocks gather_only(const cpca::DataMatrix& zeros, const cpca::DataMatrix& x, int* calls) {
  return cpca::RowBlocks(zeros, 1, {},
                         [&x, calls](const std::uint32_t* rows, Eigen::Index count, float* out) {
                           ++*calls;
                           for (Eigen::Index i = 0; i < count; ++i)
                             std::copy_n(&x(rows[i], 0), x.cols(), out + i * x.cols());
                         });
}

TEST(OutOfCore, SplitsReadTheirRowsThroughGather) {
  const cpca::DataMatrix x = grid_data(6);
  const cpca::DataMatrix zeros = cpca::DataMatrix::Zero(x.rows(), x.cols());
  std::vector<std::uint32_t> a(std::size_t(x.rows()), 0), b = a;
  int calls = 0;
  EXPECT_EQ(cpca::split_empty_clusters(x, a, 7), 6);
  EXPECT_EQ(cpca::split_empty_clusters(gather_only(zeros, x, &calls), b, 7), 6);
  EXPECT_EQ(a, b);
  EXPECT_GT(calls, 0);
}

TEST(OutOfCore, ClusterPcaOverBlocksEqualsInMemoryAndReadsThroughGather) {
  const cpca::DataMatrix x = grid_data(3);
  cpca::LbgOptions o;
  o.clusters = 9;
  for (cpca::PcaSolver solver : {cpca::PcaSolver::kPowerIteration, cpca::PcaSolver::kEigen}) {
    cpca::CompressedSet a;
    a.order = 5, a.channels = 1, a.columns = 1;
    a.cluster_count = o.clusters;
    a.component_count = 4;
    a.cluster_of = cpca::lbg(x, o).cluster_of;
    cpca::CompressedSet b = a;
    const std::vector<double> ea = cpca::fit_cluster_pca(x, a, solver);
    const cpca::DataMatrix zeros = cpca::DataMatrix::Zero(x.rows(), x.cols());
    int calls = 0;
    const std::vector<double> eb = cpca::fit_cluster_pca(gather_only(zeros, x, &calls), b, solver);
    EXPECT_EQ(ea, eb);
    EXPECT_EQ(a.means, b.means);
    EXPECT_EQ(a.bases, b.bases);
    EXPECT_EQ(a.weights, b.weights);
    EXPECT_GE(calls, o.clusters);  // every cluster's rows
  }
}

void expect_same(const cpca::CompressedSet& a, const cpca::CompressedSet& b) {
  EXPECT_EQ(a.cluster_of, b.cluster_of);
  EXPECT_EQ(a.means, b.means);
  EXPECT_EQ(a.bases, b.bases);
  EXPECT_EQ(a.weights, b.weights);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(OutOfCore, CompressOverTinyBlocksEqualsInMemoryForEveryMethod) {
  const cpca::DataMatrix x = grid_data(4);
  const cpca::Geometry geometry = cpca_test::grid(kSide);
  for (int variant = 0; variant < 3; ++variant) {
    SCOPED_TRACE("variant " + std::to_string(variant));
    cpca::CompressOptions o;
    o.layout = kLayout;
    o.clusters = 16;
    o.components = 3;
    if (variant == 1) {
      o.method = cpca::ClusterMethod::kIterative;
    } else if (variant == 2) {
      o.alpha = 0.05;
      o.overdraw_reduction = true;
    }
    cpca::CompressReport ra, rb;
    const cpca::CompressedSet a = cpca::compress(x, o, &geometry, &ra);
    const cpca::CompressedSet b = cpca::compress(cpca::RowBlocks(x, 1), o, &geometry, &rb);
    expect_same(a, b);
    EXPECT_EQ(ra.lbg_energy, rb.lbg_energy);
    EXPECT_EQ(ra.error.average_squared_error, rb.error.average_squared_error);
    EXPECT_EQ(ra.error.relative_error, rb.error.relative_error);
  }
}

TEST(OutOfCore, BlocksRoundUpToTheGranuleAndCoverEveryRow) {
  const cpca::DataMatrix x = grid_data(5);
  const cpca::RowBlocks blocks(x, 1);
  EXPECT_EQ(blocks.block_rows(), cpca::RowBlocks::kGranule);
  Eigen::Index next = 0;
  blocks.for_each([&](Eigen::Index first, const auto& block) {
    EXPECT_EQ(first, next);
    EXPECT_EQ(block(0, 0), x(first, 0));
    next += block.rows();
  });
  EXPECT_EQ(next, x.rows());
  EXPECT_EQ(cpca::RowBlocks(x).block_count(), 1);
}

TEST(OutOfCore, NonFiniteDataIsRefusedBlockByBlock) {
  cpca::DataMatrix x = grid_data(6);
  x(1400, 3) = NAN;
  cpca::CompressOptions o;
  o.layout = kLayout;
  o.clusters = 4;
  o.components = 2;
  EXPECT_THROW(cpca::compress(cpca::RowBlocks(x, 256), o), std::invalid_argument);
}

}  // namespace
