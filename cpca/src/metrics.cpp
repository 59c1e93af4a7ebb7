#include "cpca/metrics.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace cpca {

namespace {

// row(r, buffer) returns row r of the reconstruction (a view, or `buffer` filled).
template <class Row>
ErrorMetrics accumulate(const Eigen::Ref<const DataMatrix>& data, Row&& row) {
  const Eigen::Index rows = data.rows();
  if (rows == 0) return {};
  // Fixed block size so the reduction order does not depend on the thread count.
  constexpr Eigen::Index kBlock = 1024;
  const Eigen::Index blocks = (rows + kBlock - 1) / kBlock;
  struct Partial {
    double err = 0, norm = 0, max = 0;
  };
  std::vector<Partial> partials(blocks);
  tbb::parallel_for(Eigen::Index(0), blocks, [&](Eigen::Index b) {
    Partial& p = partials[b];
    Eigen::RowVectorXf buffer(data.cols());
    const Eigen::Index end = std::min(rows, (b + 1) * kBlock);
    for (Eigen::Index r = b * kBlock; r < end; ++r) {
      const double e = (data.row(r) - row(r, buffer)).template cast<double>().squaredNorm();
      p.err += e;
      p.norm += data.row(r).template cast<double>().squaredNorm();
      p.max = std::max(p.max, e);
    }
  });
  Partial total;
  for (const Partial& p : partials) {
    total.err += p.err;
    total.norm += p.norm;
    total.max = std::max(total.max, p.max);
  }
  ErrorMetrics m;
  m.average_squared_error = total.err / double(rows);
  m.relative_error = total.norm > 0 ? total.err / total.norm : 0.0;
  m.max_squared_error = total.max;
  return m;
}

}  // namespace

ErrorMetrics error_metrics(const Eigen::Ref<const DataMatrix>& data,
                           const Eigen::Ref<const DataMatrix>& reconstruction) {
  if (data.rows() != reconstruction.rows() || data.cols() != reconstruction.cols()) {
    throw std::invalid_argument("error_metrics: data is " + std::to_string(data.rows()) + "x" +
                                std::to_string(data.cols()) + " but reconstruction is " +
                                std::to_string(reconstruction.rows()) + "x" +
                                std::to_string(reconstruction.cols()));
  }
  return accumulate(data,
                    [&](Eigen::Index r, Eigen::RowVectorXf&) { return reconstruction.row(r); });
}

ErrorMetrics error_metrics_by_row(const Eigen::Ref<const DataMatrix>& data,
                                  const std::function<void(Eigen::Index, float*)>& reconstruct) {
  return accumulate(data,
                    [&](Eigen::Index r, Eigen::RowVectorXf& buffer) -> const Eigen::RowVectorXf& {
                      reconstruct(r, buffer.data());
                      return buffer;
                    });
}

SizeMetrics size_metrics(std::uint64_t vertices, std::uint64_t dimension, std::uint64_t clusters,
                         std::uint64_t components) {
  SizeMetrics s;
  s.raw_numbers = vertices * dimension;
  s.compressed_numbers = vertices * components + clusters * (components + 1) * dimension;
  s.ratio = s.compressed_numbers ? double(s.raw_numbers) / double(s.compressed_numbers) : 0.0;
  return s;
}

}  // namespace cpca
