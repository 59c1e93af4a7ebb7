#include "cpca/compressed.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cpca {

void reconstruct_vertex(const CompressedSet& set, std::uint64_t p, float* out) {
  const int k = int(set.cluster_of[p]);
  Eigen::Map<Eigen::Matrix<float, 1, Eigen::Dynamic>> row(out, Eigen::Index(set.dimension()));
  row = set.mean(k);
  if (set.component_count > 0) row.noalias() += set.weight_row(p) * set.basis(k);
}

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("compressed set: " + what);
}

bool all_finite(const std::vector<float>& v) {
  for (float x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

}  // namespace

void validate(const CompressedSet& set) {
  require(set.order >= 1 && set.order <= 10,
          "SH order " + std::to_string(set.order) + " is outside 1..10");
  require(set.channels == 1 || set.channels == 3,
          "channel count " + std::to_string(set.channels) + " is not 1 or 3");
  require(set.columns == 1 || set.columns == set.coefficient_count(),
          "column count " + std::to_string(set.columns) + " is neither 1 nor n");
  validate_arrays(set);
}

void validate_arrays(const CompressedSet& set) {
  require(set.vertex_count >= 1, "no vertices");
  require(set.cluster_count >= 1 && std::uint64_t(set.cluster_count) <= set.vertex_count,
          "cluster count " + std::to_string(set.cluster_count) + " is outside 1..vertices");
  require(set.component_count >= 0 && std::size_t(set.component_count) <= set.dimension(),
          "component count " + std::to_string(set.component_count) + " is outside 0..dimension");
  const std::size_t v = set.vertex_count, k = std::size_t(set.cluster_count),
                    n = std::size_t(set.component_count), d = set.dimension();
  require(set.cluster_of.size() == v, "cluster id array has the wrong length");
  require(set.weights.size() == v * n, "weight array has the wrong length");
  require(set.means.size() == k * d, "mean array has the wrong length");
  require(set.bases.size() == k * n * d, "basis array has the wrong length");
  for (std::size_t p = 0; p < v; ++p)
    require(set.cluster_of[p] < k, "vertex " + std::to_string(p) + " has cluster id " +
                                       std::to_string(set.cluster_of[p]) +
                                       " >= " + std::to_string(k));
  require(all_finite(set.weights), "a weight is NaN or infinite");
  require(all_finite(set.means), "a mean value is NaN or infinite");
  require(all_finite(set.bases), "a basis value is NaN or infinite");
}

}  // namespace cpca
