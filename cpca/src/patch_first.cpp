// Patch-first CPCA: METIS patches, then CPCA inside each.
#include "cpca/patch_first.h"

#include "cpca/compress.h"
#include "metis_kway.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace cpca {
namespace {

using Edge = std::pair<std::uint32_t, std::uint32_t>;

// Every mesh edge once, (low, high), sorted.
std::vector<Edge> mesh_edges(const Geometry& g) {
  std::vector<Edge> edges;
  edges.reserve(g.triangles.size() * 3);
  for (const TriangleIndices& t : g.triangles)
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = t[i], b = t[(i + 1) % 3];
      if (a != b) edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

// Similar neighbours are expensive to cut, so borders follow changes of the signal.
std::vector<std::uint32_t> similarity_weights(const Eigen::Ref<const DataMatrix>& data,
                                              const std::vector<Edge>& edges) {
  std::vector<double> d(edges.size());
  tbb::parallel_for(std::size_t(0), edges.size(), [&](std::size_t e) {
    d[e] = (data.row(edges[e].first) - data.row(edges[e].second)).cast<double>().squaredNorm();
  });
  double mean = 0;
  for (double v : d) mean += v;
  mean = edges.empty() ? 0.0 : mean / double(edges.size());
  std::vector<std::uint32_t> w(edges.size(), 1);
  if (mean > 0)
    for (std::size_t e = 0; e < edges.size(); ++e)
      w[e] = 1 + std::uint32_t(std::lround(100.0 * std::exp(-d[e] / mean)));
  return w;
}

std::vector<std::uint32_t> metis_patches(std::size_t vertices, const std::vector<Edge>& edges,
                                         const std::vector<std::uint32_t>& weight,
                                         const std::vector<int>& counts, std::uint64_t seed,
                                         const std::vector<std::uint32_t>& vertex_weight) {
  KwayGraph g;
  g.node_weight = vertex_weight;
  g.offset.assign(vertices + 1, 0);
  for (const Edge& e : edges) ++g.offset[e.first + 1], ++g.offset[e.second + 1];
  for (std::size_t v = 0; v < vertices; ++v) g.offset[v + 1] += g.offset[v];
  g.neighbor.resize(g.offset.back());
  g.weight.resize(g.offset.back());
  std::vector<std::uint32_t> fill(g.offset.begin(), g.offset.end() - 1);
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const std::uint32_t a = edges[e].first, b = edges[e].second;
    g.neighbor[fill[a]] = b, g.weight[fill[a]++] = weight[e];
    g.neighbor[fill[b]] = a, g.weight[fill[b]++] = weight[e];
  }
  int total = 0;
  for (int c : counts) total += c;
  KwayOptions o;
  o.parts = int(counts.size());
  o.seed = seed;
  for (int c : counts) o.shares.push_back(float(c) / float(total));
  o.nodes = "vertices";
  // METIS's default leaves patches free to be non-contiguous: disjoint meshes cannot be.
  return metis_kway(g, o);
}

// A patch needs a vertex per cluster. Short patches take vertices from patches with spare
// ones, preferring a vertex adjacent to the short patch so that it stays compact.
void repair_short_patches(std::vector<std::uint32_t>& patch_of, const std::vector<Edge>& edges,
                          const std::vector<int>& counts) {
  std::vector<std::int64_t> size(counts.size(), 0);
  for (std::uint32_t p : patch_of) ++size[p];
  const auto spare = [&](std::uint32_t q) { return size[q] > counts[q]; };
  for (std::uint32_t p = 0; p < counts.size(); ++p)
    while (size[p] < counts[p]) {
      std::int64_t pick = -1;
      for (const Edge& e : edges) {
        const std::uint32_t a = patch_of[e.first], b = patch_of[e.second];
        if (a == p && b != p && spare(b)) pick = e.second;
        if (b == p && a != p && spare(a)) pick = e.first;
        if (pick >= 0) break;
      }
      for (std::size_t v = 0; pick < 0 && v < patch_of.size(); ++v)
        if (patch_of[v] != p && spare(patch_of[v])) pick = std::int64_t(v);
      --size[patch_of[std::size_t(pick)]];
      patch_of[std::size_t(pick)] = p;
      ++size[p];
    }
}

// The patch's rows, and its triangles renumbered into them (only those wholly inside).
struct Patch {
  std::vector<std::uint32_t> vertices;
  DataMatrix data;
  Geometry geometry;
};

Patch extract_patch(const Eigen::Ref<const DataMatrix>& data, const Geometry& g,
                    const std::vector<std::uint32_t>& patch_of, std::uint32_t p) {
  Patch patch;
  std::vector<std::uint32_t> local(patch_of.size(), ~0u);
  for (std::uint32_t v = 0; v < patch_of.size(); ++v)
    if (patch_of[v] == p) {
      local[v] = std::uint32_t(patch.vertices.size());
      patch.vertices.push_back(v);
      patch.geometry.positions.push_back(g.positions[v]);
    }
  patch.data.resize(Eigen::Index(patch.vertices.size()), data.cols());
  for (std::size_t i = 0; i < patch.vertices.size(); ++i)
    patch.data.row(Eigen::Index(i)) = data.row(patch.vertices[i]);
  for (const TriangleIndices& t : g.triangles)
    if (local[t[0]] != ~0u && local[t[1]] != ~0u && local[t[2]] != ~0u)
      patch.geometry.triangles.push_back({local[t[0]], local[t[1]], local[t[2]]});
  return patch;
}

// Copies a patch's clusters into the whole set as clusters first, first + 1, ...
void stitch(const CompressedSet& part, const Patch& patch, int first, CompressedSet& set) {
  const std::size_t d = set.dimension(), n = std::size_t(set.component_count);
  for (std::size_t i = 0; i < patch.vertices.size(); ++i) {
    const std::uint32_t v = patch.vertices[i];
    set.cluster_of[v] = std::uint32_t(first) + part.cluster_of[i];
    std::copy_n(part.weights.begin() + std::ptrdiff_t(i * n), n,
                set.weights.begin() + std::ptrdiff_t(std::size_t(v) * n));
  }
  const std::size_t k = std::size_t(part.cluster_count);
  std::copy_n(part.means.begin(), k * d, set.means.begin() + std::ptrdiff_t(first * d));
  std::copy_n(part.bases.begin(), k * n * d,
              set.bases.begin() + std::ptrdiff_t(std::size_t(first) * n * d));
}

}  // namespace

std::vector<int> patch_cluster_counts(int cluster_count, int per_pass) {
  if (cluster_count < 1 || per_pass < 1)
    throw std::invalid_argument("patch-first: clusters and clusters per pass must be >= 1, got " +
                                std::to_string(cluster_count) + " and " + std::to_string(per_pass));
  std::vector<int> counts;
  for (int left = cluster_count; left > 0; left -= per_pass)
    counts.push_back(std::min(left, per_pass));
  return counts;
}

std::vector<std::uint32_t> cluster_density_weights(const std::vector<std::uint32_t>& cluster_of,
                                                   int cluster_count) {
  std::vector<std::uint64_t> size(std::size_t(std::max(cluster_count, 1)), 0);
  for (std::uint32_t c : cluster_of) {
    if (c >= size.size())
      throw std::invalid_argument("cluster density weights: a vertex names cluster " +
                                  std::to_string(c) + " of " + std::to_string(cluster_count));
    ++size[c];
  }
  // A cluster's vertices weigh `unit` together, and all of them together about 1e9 < 2^31.
  const double unit = 1e9 / double(size.size());
  std::vector<std::uint32_t> weight;
  weight.reserve(cluster_of.size());
  for (std::uint32_t c : cluster_of)
    weight.push_back(std::uint32_t(std::max(1.0, std::round(unit / double(size[c])))));
  return weight;
}

std::vector<std::uint32_t> partition_patches(const Eigen::Ref<const DataMatrix>& data,
                                             const Geometry& geometry,
                                             const std::vector<int>& counts, std::uint64_t seed,
                                             const std::vector<std::uint32_t>& vertex_weight) {
  const std::size_t vertices = std::size_t(data.rows());
  if (!vertex_weight.empty() && vertex_weight.size() != vertices)
    throw std::invalid_argument("patch-first: " + std::to_string(vertex_weight.size()) +
                                " vertex weights for " + std::to_string(vertices) + " vertices");
  std::int64_t total = 0;
  for (int c : counts) total += c;
  if (total > std::int64_t(vertices) || geometry.positions.size() != vertices)
    throw std::invalid_argument("patch-first: " + std::to_string(total) + " clusters need as " +
                                "many vertices, and the mesh must match the data's " +
                                std::to_string(vertices) + " rows");
  if (counts.size() == 1) return std::vector<std::uint32_t>(vertices, 0);
  const std::vector<Edge> edges = mesh_edges(geometry);
  std::vector<std::uint32_t> patch_of =
      metis_patches(vertices, edges, similarity_weights(data, edges), counts, seed, vertex_weight);
  repair_short_patches(patch_of, edges, counts);
  return patch_of;
}

double equal_patches_overdraw(const Geometry& geometry, int passes, std::uint64_t seed) {
  const std::size_t vertices = geometry.positions.size();
  if (passes < 1 || std::size_t(passes) > vertices)
    throw std::invalid_argument("equal patches: " + std::to_string(passes) + " passes for " +
                                std::to_string(vertices) + " vertices");
  if (passes == 1) return 1.0;
  const std::vector<Edge> edges = mesh_edges(geometry);
  const std::vector<std::uint32_t> patch_of =
      metis_patches(vertices, edges, std::vector<std::uint32_t>(edges.size(), 1),
                    std::vector<int>(std::size_t(passes), 1), seed, {});
  // Each patch a cluster alone in its pass: cpca::overdraw counts the draws.
  return overdraw(patch_of, geometry.triangles, group_in_order(passes, 1)).average_overdraw;
}

CompressedSet compress_patch_first(const Eigen::Ref<const DataMatrix>& data,
                                   const CompressOptions& options, const Geometry& geometry,
                                   CompressReport* report) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<int> counts = patch_cluster_counts(options.clusters, options.clusters_per_pass);
  // patch-eps balances its patches by original CPCA's allocation of clusters over the surface
  // (cluster_density_weights), so the passes follow the signal's complexity.
  const std::vector<std::uint32_t> weight =
      options.method == ClusterMethod::kPatchEpsilon && !options.reference_clusters.empty()
          ? cluster_density_weights(options.reference_clusters, options.clusters)
          : std::vector<std::uint32_t>{};
  const std::vector<std::uint32_t> patch_of =
      partition_patches(data, geometry, counts, options.seed, weight);
  // Each patch is compressed alone, so the whole set is built from ordinary compressions.
  CompressOptions inner = options;
  // patch-eps refines the whole set afterwards with its own refits, so its patches stop at
  // LBG + PCA instead of running iterative CPCA inside each.
  inner.method = options.method == ClusterMethod::kPatchEpsilon ? ClusterMethod::kLbg
                                                                : ClusterMethod::kIterative;
  CompressedSet set;
  std::vector<CompressedSet> parts(counts.size());
  std::vector<Patch> patches(counts.size());
  tbb::parallel_for(std::size_t(0), counts.size(), [&](std::size_t p) {
    patches[p] = extract_patch(data, geometry, patch_of, std::uint32_t(p));
    CompressOptions o = inner;
    o.clusters = counts[p];
    parts[p] = compress(patches[p].data, o, &patches[p].geometry);
  });
  set = parts.front();
  set.method = ClusterMethod::kPatchFirst;
  set.overdraw_reduction = options.overdraw_reduction;
  set.cluster_count = options.clusters;
  set.vertex_count = std::uint64_t(data.rows());
  set.cluster_of.assign(std::size_t(data.rows()), 0);
  set.weights.assign(std::size_t(data.rows()) * std::size_t(set.component_count), 0.f);
  set.means.assign(std::size_t(options.clusters) * set.dimension(), 0.f);
  set.bases.assign(
      std::size_t(options.clusters) * std::size_t(set.component_count) * set.dimension(), 0.f);
  set.iterations = 0;
  for (std::size_t p = 0; p < counts.size(); ++p) {
    stitch(parts[p], patches[p], int(p) * options.clusters_per_pass, set);
    set.iterations = std::max(set.iterations, parts[p].iterations);
  }
  if (report) {
    *report = CompressReport{};
    report->lbg_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    report->error = error_metrics(data, set);
    report->size = size_metrics(std::uint64_t(data.rows()), std::uint64_t(data.cols()),
                                std::uint64_t(options.clusters), std::uint64_t(options.components));
    report->has_geometry = true;
    report->span = triangle_span(set.cluster_of, geometry.triangles);
    report->total_seconds = report->lbg_seconds;
  }
  return set;
}

}  // namespace cpca
