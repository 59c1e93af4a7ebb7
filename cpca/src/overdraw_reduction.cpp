#include "cpca/overdraw_reduction.h"

#include "cpca/cluster_pca.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace cpca {
namespace {

// Vertex -> incident triangles, CSR: vertex p's triangles are incident[start[p] .. start[p+1]).
struct Incidence {
  std::vector<std::uint32_t> start, incident;
};

Incidence incident_triangles(const Geometry& geometry, std::size_t v) {
  Incidence c;
  c.start.assign(v + 1, 0);
  for (const TriangleIndices& t : geometry.triangles)
    for (std::uint32_t i : t) {
      if (i >= v) throw std::invalid_argument("overdraw reduction: triangle index out of range");
      ++c.start[i + 1];
    }
  std::partial_sum(c.start.begin(), c.start.end(), c.start.begin());
  c.incident.resize(c.start[v]);
  std::vector<std::uint32_t> fill(c.start.begin(), c.start.end() - 1);
  for (std::size_t t = 0; t < geometry.triangles.size(); ++t)
    for (std::uint32_t i : geometry.triangles[t]) c.incident[fill[i]++] = std::uint32_t(t);
  return c;
}

}  // namespace

OverdrawReductionResult reduce_overdraw(const Eigen::Ref<const DataMatrix>& x,
                                        const Geometry& geometry, CompressedSet& set,
                                        const std::vector<double>& vertex_error,
                                        const OverdrawReductionOptions& options) {
  const std::size_t v = std::size_t(x.rows());
  if (geometry.positions.size() != v || vertex_error.size() != v || set.cluster_of.size() != v)
    throw std::invalid_argument("overdraw reduction: mesh has " +
                                std::to_string(geometry.positions.size()) +
                                " vertices but the data has " + std::to_string(v) + " rows");
  if (!(options.tolerance >= 0))
    throw std::invalid_argument("overdraw reduction: tolerance must be >= 0");
  const Incidence incidence = incident_triangles(geometry, v);
  const std::vector<std::uint32_t>& start = incidence.start;
  const std::vector<std::uint32_t>& incident = incidence.incident;
  std::vector<std::uint32_t>& cluster = set.cluster_of;
  std::vector<std::size_t> count(std::size_t(set.cluster_count), 0);
  for (std::uint32_t c : cluster) ++count[c];
  const double average = std::accumulate(vertex_error.begin(), vertex_error.end(), 0.0) / double(v);
  const double budget = options.tolerance * average;
  std::vector<double> error = vertex_error;  // err(p, cluster_of[p]) as moves happen

  auto span = [&](std::uint32_t p, std::uint32_t c) {
    int total = 0;
    for (std::uint32_t s = start[p]; s < start[p + 1]; ++s) {
      const TriangleIndices& t = geometry.triangles[incident[s]];
      std::uint32_t seen[3];
      int distinct = 0;
      for (std::uint32_t q : t) {
        const std::uint32_t k = q == p ? c : cluster[q];
        if (std::find(seen, seen + distinct, k) == seen + distinct) seen[distinct++] = k;
      }
      total += distinct;
    }
    return total;
  };

  OverdrawReductionResult result;
  std::vector<std::uint32_t> candidates;
  for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
    std::uint64_t moved = 0;
    for (std::uint32_t p = 0; p < v; ++p) {
      const std::uint32_t a = cluster[p];
      candidates.clear();
      for (std::uint32_t s = start[p]; s < start[p + 1]; ++s)
        for (std::uint32_t q : geometry.triangles[incident[s]])
          if (cluster[q] != a &&
              std::find(candidates.begin(), candidates.end(), cluster[q]) == candidates.end())
            candidates.push_back(cluster[q]);
      if (candidates.empty() || count[a] <= 1) continue;
      const int current = span(p, a);
      int best_span = current;
      double best_err = 0;
      std::uint32_t best = a;
      std::sort(candidates.begin(), candidates.end());  // ties to the lowest id
      for (std::uint32_t c : candidates) {
        const int s = span(p, c);
        if (s >= current || s > best_span) continue;
        const double e = subspace_distance(x.row(p), set, int(c));
        if (e - error[p] > budget) continue;
        if (s < best_span || e < best_err) {
          best_span = s;
          best_err = e;
          best = c;
        }
      }
      if (best == a) continue;
      result.error_increase += best_err - error[p];
      error[p] = best_err;
      --count[a];
      ++count[best];
      cluster[p] = best;
      ++moved;
    }
    result.sweeps = sweep + 1;
    result.moves += moved;
    if (moved == 0) break;
  }
  return result;
}

}  // namespace cpca
