// cpca/assignment.h: assigning points to clusters from a matrix of squared data distances,
// plainly (argmin) or with the geometry coherence of thesis eq. 9-10.
//
// Geometry coherence, with the scales made explicit (the thesis leaves them implicit):
//   E_ij = ||x_i - m_j|| / s  +  alpha * min_{k in j, k != i} ||P_i - P_k|| / diag
// where s is the RMS data distance of the previous assignment (sqrt(energy / V)), so that
// the data term of a typical point is ~1 whatever the transfer's units, and positions are
// divided by the mesh's bounding-box diagonal, so the geometric term is in [0, 1]. Cluster
// membership for the min is the previous iteration's. The point itself is excluded (eq. 10 is
// meant as "how close is the cluster", not "am I in it"); a cluster whose only member is the
// point itself counts as distance 0. With alpha = 0 the result is exactly the argmin of the
// squared distances, ties going to the lowest cluster index in both paths.
#pragma once

#include "cpca/geometry.h"
#include "cpca/metrics.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace cpca {

// ||x_i||^2 - 2 x_i . c_j + ||c_j||^2, V x K, as one matrix product per row block (parallel),
// clamped at 0. `x_squared_norms` holds ||x_i||^2.
DataMatrix squared_distances(const Eigen::Ref<const DataMatrix>& x,
                             const Eigen::VectorXf& x_squared_norms,
                             const Eigen::Ref<const DataMatrix>& centroids);

// Per row, the column of the smallest value (lowest index on ties).
std::vector<std::uint32_t> argmin_rows(const DataMatrix& cost);

class GeometryCoherence {
 public:
  // Throws std::invalid_argument when positions do not match `vertex_count` or alpha < 0.
  GeometryCoherence(const Geometry& geometry, std::size_t vertex_count, double alpha);

  // New assignment from squared data distances (V x K) and the previous assignment.
  // `data_scale` is s above (must be > 0; the caller passes sqrt(previous energy / V)).
  std::vector<std::uint32_t> assign(const DataMatrix& squared_distance,
                                    const std::vector<std::uint32_t>& previous,
                                    double data_scale) const;

  double alpha() const { return alpha_; }

 private:
  std::vector<Eigen::Vector3f> positions_;  // divided by the bounding-box diagonal
  double alpha_;
};

}  // namespace cpca
