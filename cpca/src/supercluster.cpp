#include "cpca/supercluster.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace cpca {

std::vector<std::uint32_t> pass_of_clusters(const SuperClusters& groups, int cluster_count) {
  constexpr std::uint32_t kUnset = ~0u;
  std::vector<std::uint32_t> pass_of(std::size_t(cluster_count), kUnset);
  for (std::size_t p = 0; p < groups.passes.size(); ++p) {
    for (std::uint32_t k : groups.passes[p]) {
      if (k >= std::uint32_t(cluster_count))
        throw std::invalid_argument("super-clusters: cluster id " + std::to_string(k) +
                                    " >= cluster count " + std::to_string(cluster_count));
      if (pass_of[k] != kUnset)
        throw std::invalid_argument("super-clusters: cluster " + std::to_string(k) +
                                    " is in two passes");
      pass_of[k] = std::uint32_t(p);
    }
  }
  for (int k = 0; k < cluster_count; ++k)
    if (pass_of[std::size_t(k)] == kUnset)
      throw std::invalid_argument("super-clusters: cluster " + std::to_string(k) +
                                  " is in no pass");
  return pass_of;
}

SuperClusters group_in_order(int cluster_count, int per_pass) {
  if (per_pass < 1) throw std::invalid_argument("group_in_order: per_pass must be >= 1");
  SuperClusters groups;
  for (int k = 0; k < cluster_count; ++k) {
    if (k % per_pass == 0) groups.passes.emplace_back();
    groups.passes.back().push_back(std::uint32_t(k));
  }
  groups.pass_of = pass_of_clusters(groups, cluster_count);
  return groups;
}

namespace {

// The distinct passes of triangle t, written to `out`; returns how many (1..3).
int passes_of_triangle(const std::vector<std::uint32_t>& cluster_of,
                       const std::vector<std::uint32_t>& pass_of, const TriangleIndices& t,
                       std::uint32_t out[3]) {
  int count = 0;
  for (std::uint32_t v : t) {
    const std::uint32_t p = pass_of[cluster_of[v]];
    if (std::find(out, out + count, p) == out + count) out[count++] = p;
  }
  return count;
}

std::vector<std::uint32_t> checked_pass_of(const std::vector<std::uint32_t>& cluster_of,
                                           const SuperClusters& groups) {
  std::uint32_t max_id = 0;
  for (std::uint32_t k : cluster_of) max_id = std::max(max_id, k);
  int cluster_count = int(groups.pass_of.size());
  if (cluster_count == 0 || groups.pass_of.size() <= max_id) {
    for (const auto& pass : groups.passes)
      for (std::uint32_t k : pass) cluster_count = std::max(cluster_count, int(k) + 1);
  }
  if (!cluster_of.empty() && std::uint32_t(cluster_count) <= max_id)
    throw std::invalid_argument("super-clusters: cluster id " + std::to_string(max_id) +
                                " is in no pass");
  return groups.pass_of.size() == std::size_t(cluster_count)
             ? groups.pass_of
             : pass_of_clusters(groups, cluster_count);
}

}  // namespace

OverdrawStats overdraw(const std::vector<std::uint32_t>& cluster_of,
                       const std::vector<TriangleIndices>& triangles, const SuperClusters& groups) {
  const std::vector<std::uint32_t> pass_of = checked_pass_of(cluster_of, groups);
  OverdrawStats stats;
  stats.triangles_per_pass.assign(groups.passes.size(), 0);
  stats.triangle_count = triangles.size();
  for (const TriangleIndices& t : triangles) {
    std::uint32_t p[3];
    const int count = passes_of_triangle(cluster_of, pass_of, t, p);
    for (int i = 0; i < count; ++i) ++stats.triangles_per_pass[p[i]];
    stats.triangles_drawn += std::uint64_t(count);
  }
  stats.average_overdraw =
      triangles.empty() ? 1.0 : double(stats.triangles_drawn) / double(triangles.size());
  return stats;
}

std::vector<std::vector<std::uint32_t>> triangles_per_pass(
    const std::vector<std::uint32_t>& cluster_of, const std::vector<TriangleIndices>& triangles,
    const SuperClusters& groups) {
  const std::vector<std::uint32_t> pass_of = checked_pass_of(cluster_of, groups);
  std::vector<std::vector<std::uint32_t>> lists(groups.passes.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    std::uint32_t p[3];
    const int count = passes_of_triangle(cluster_of, pass_of, triangles[i], p);
    for (int j = 0; j < count; ++j) lists[p[j]].push_back(std::uint32_t(i));
  }
  return lists;
}

std::vector<std::uint8_t> triangle_pass_counts(const std::vector<std::uint32_t>& cluster_of,
                                               const std::vector<TriangleIndices>& triangles,
                                               const SuperClusters& groups) {
  const std::vector<std::uint32_t> pass_of = checked_pass_of(cluster_of, groups);
  std::vector<std::uint8_t> counts(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    std::uint32_t p[3];
    counts[i] = std::uint8_t(passes_of_triangle(cluster_of, pass_of, triangles[i], p));
  }
  return counts;
}

}  // namespace cpca
