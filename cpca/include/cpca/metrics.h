// cpca/metrics.h: error and size measures of a compressed transfer set (thesis ch. 3.1.3
// and the result tables 5.2-5.17; docs/ARCHITECTURE.md "Compression").
//
// Data is a V x D matrix, one row per vertex (x_p = vec(M_p), all channels concatenated);
// the reconstruction has the same shape.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <functional>

namespace cpca {

using DataMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct ErrorMetrics {
  double average_squared_error = 0.0;  // (1/V) sum_p |x_p - xhat_p|^2: the thesis's "Average SE"
  double relative_error = 0.0;         // sum |x - xhat|^2 / sum |x|^2 (0 when the data is 0)
  double max_squared_error = 0.0;      // worst vertex
};

// Accumulates in double, rows in parallel blocks reduced in a fixed order (deterministic).
ErrorMetrics error_metrics(const Eigen::Ref<const DataMatrix>& data,
                           const Eigen::Ref<const DataMatrix>& reconstruction);

// The same measures of a reconstruction made one row at a time (reconstruct(r, out) writes
// row r's data.cols() floats), with the same blocks and arithmetic as the matrix form: a
// compressed set's error without a V x D copy of the data (180 MB on the bunny).
ErrorMetrics error_metrics_by_row(const Eigen::Ref<const DataMatrix>& data,
                                  const std::function<void(Eigen::Index, float*)>& reconstruct);

// Numbers stored: raw V * D; compressed V * N + K * (N + 1) * D (thesis ch. 3.1.3; the
// cluster ids, one per vertex, are not counted there and are reported separately).
struct SizeMetrics {
  std::uint64_t raw_numbers = 0;
  std::uint64_t compressed_numbers = 0;
  double ratio = 0.0;  // raw / compressed
};

SizeMetrics size_metrics(std::uint64_t vertices, std::uint64_t dimension, std::uint64_t clusters,
                         std::uint64_t components);

}  // namespace cpca
