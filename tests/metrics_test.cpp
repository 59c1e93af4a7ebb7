#include "cpca/metrics.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

namespace {

TEST(Metrics, ErrorsMatchHandComputation) {
  cpca::DataMatrix x(3, 2), y(3, 2);
  x << 1, 2, 3, 4, 0, 0;
  y << 1, 2, 2, 4, 0, 1;  // row errors 0, 1, 1
  const cpca::ErrorMetrics m = cpca::error_metrics(x, y);
  EXPECT_DOUBLE_EQ(m.average_squared_error, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(m.relative_error, 2.0 / 30.0);
  EXPECT_DOUBLE_EQ(m.max_squared_error, 1.0);
  EXPECT_THROW(cpca::error_metrics(x, cpca::DataMatrix(2, 2)), std::invalid_argument);
}

TEST(Metrics, LargeInputIsIndependentOfThreadCountAndMatchesEigen) {
  // Blocks reduce in a fixed order (docs/ARCHITECTURE.md), so one thread and all threads
  // must give the same bits; running the same call twice would not show an order that
  // depends on scheduling.
  cpca::DataMatrix x = cpca::DataMatrix::Random(5000, 17), y = cpca::DataMatrix::Random(5000, 17);
  const cpca::ErrorMetrics a = cpca::error_metrics(x, y);
  cpca::ErrorMetrics b;
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    b = cpca::error_metrics(x, y);
  }
  EXPECT_EQ(a.average_squared_error, b.average_squared_error);
  EXPECT_EQ(a.max_squared_error, b.max_squared_error);
  EXPECT_EQ(a.relative_error, b.relative_error);
  const double oracle = (x - y).cast<double>().squaredNorm() / 5000.0;
  EXPECT_NEAR(a.average_squared_error, oracle, 1e-9 * oracle);
}

TEST(Metrics, RowByRowFormEqualsTheMatrixForm) {
  // The compressed set's metrics reconstruct one row at a time; same blocks, same arithmetic,
  // so the same bits as the matrix form, also on one thread.
  cpca::DataMatrix x = cpca::DataMatrix::Random(3000, 23), y = cpca::DataMatrix::Random(3000, 23);
  const cpca::ErrorMetrics matrix = cpca::error_metrics(x, y);
  const auto row = [&](Eigen::Index r, float* out) {
    Eigen::Map<Eigen::RowVectorXf>(out, y.cols()) = y.row(r);
  };
  cpca::ErrorMetrics by_row = cpca::error_metrics_by_row(x, row), one;
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    one = cpca::error_metrics_by_row(x, row);
  }
  for (const cpca::ErrorMetrics& m : {by_row, one}) {
    EXPECT_EQ(m.average_squared_error, matrix.average_squared_error);
    EXPECT_EQ(m.relative_error, matrix.relative_error);
    EXPECT_EQ(m.max_squared_error, matrix.max_squared_error);
  }
  EXPECT_EQ(cpca::error_metrics_by_row(cpca::DataMatrix(0, 4), row).average_squared_error, 0.0);
}

TEST(Metrics, ThesisSizeFormula) {
  // Bunny, order 6 glossy grey (36*36 = 1296 numbers per vertex), 256 clusters, 8 PCs.
  const cpca::SizeMetrics s = cpca::size_metrics(34835, 1296, 256, 8);
  EXPECT_EQ(s.raw_numbers, 34835ull * 1296);
  EXPECT_EQ(s.compressed_numbers, 34835ull * 8 + 256ull * 9 * 1296);
  EXPECT_NEAR(s.ratio, 45146160.0 / 3264664.0, 1e-9);
}

}  // namespace
