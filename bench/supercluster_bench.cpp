// Super-cluster strategies on a real mesh: average triangle overdraw and run time of every
// registered strategy (cpca/supercluster_strategy.h) for several cluster counts and
// clusters-per-pass settings. Until the CPCA clustering of a bake is wired in, clusters come
// from k-means (Lloyd, k-means++ seeding, fixed seed) of
//   positions: compact patches, the geometry-coherent extreme (small overdraw);
//   normals:   scattered patches, a stand-in for PRT clusters, whose transfer mostly
//              follows the normal (the hard case the thesis's tables describe).
// Usage: supercluster_bench [MESH] [CLUSTERS,...] [PER_PASS,...]
#include "cpca/supercluster.h"
#include "cpca/supercluster_strategy.h"
#include "meshes/load.h"

#include <Eigen/Core>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<int> parse_list(const char* text) {
  std::vector<int> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) values.push_back(std::stoi(item));
  return values;
}

// Lloyd's k-means on points, k-means++ seeding; clusters left empty take the point
// farthest from its centre so every id is used.
std::vector<std::uint32_t> kmeans(const std::vector<meshes::Vec3>& points, int k,
                                  std::uint32_t seed) {
  const std::size_t n = points.size();
  std::mt19937 rng(seed);
  std::vector<meshes::Vec3> centres{points[rng() % n]};
  std::vector<float> d2(n, std::numeric_limits<float>::max());
  while (int(centres.size()) < k) {
    double total = 0;
    for (std::size_t i = 0; i < n; ++i) {
      d2[i] = std::min(d2[i], (points[i] - centres.back()).squaredNorm());
      total += d2[i];
    }
    double r = std::uniform_real_distribution<double>(0.0, total)(rng);
    std::size_t pick = 0;
    while (pick + 1 < n && (r -= d2[pick]) > 0) ++pick;
    centres.push_back(points[pick]);
  }
  std::vector<std::uint32_t> label(n, 0);
  for (int iteration = 0; iteration < 30; ++iteration) {
    std::vector<float> best_d(n);
    for (std::size_t i = 0; i < n; ++i) {
      float best = std::numeric_limits<float>::max();
      for (int c = 0; c < k; ++c) {
        const float d = (points[i] - centres[std::size_t(c)]).squaredNorm();
        if (d < best) best = d, label[i] = std::uint32_t(c);
      }
      best_d[i] = best;
    }
    std::vector<meshes::Vec3> sum(std::size_t(k), meshes::Vec3::Zero());
    std::vector<int> count(std::size_t(k), 0);
    for (std::size_t i = 0; i < n; ++i) sum[label[i]] += points[i], ++count[label[i]];
    for (int c = 0; c < k; ++c) {
      if (count[std::size_t(c)] > 0) {
        centres[std::size_t(c)] = sum[std::size_t(c)] / float(count[std::size_t(c)]);
        continue;
      }
      std::size_t far = 0;
      for (std::size_t i = 1; i < n; ++i)
        if (best_d[i] > best_d[far]) far = i;
      centres[std::size_t(c)] = points[far];
      label[far] = std::uint32_t(c);
      best_d[far] = 0;
    }
  }
  return label;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "/usr/share/glmark2/models/bunny.obj";
  const std::vector<int> cluster_counts = parse_list(argc > 2 ? argv[2] : "64,128,192,256");
  const std::vector<int> per_passes = parse_list(argc > 3 ? argv[3] : "3,16");
  const meshes::Mesh mesh = meshes::load_mesh(path);
  std::vector<cpca::TriangleIndices> triangles(mesh.triangles.begin(), mesh.triangles.end());
  std::printf("# %s: %zu vertices, %zu triangles\n\n", path.c_str(), mesh.vertex_count(),
              mesh.triangle_count());
  std::printf("| clustering | K | per pass | passes | strategy | overdraw | seconds |\n");
  std::printf("| --- | ---: | ---: | ---: | --- | ---: | ---: |\n");
  for (const char* feature : {"positions", "normals"}) {
    const std::vector<meshes::Vec3>& points =
        std::string(feature) == "positions" ? mesh.positions : mesh.normals;
    for (int k : cluster_counts) {
      const std::vector<std::uint32_t> cluster_of = kmeans(points, k, 12345u);
      for (int per_pass : per_passes) {
        const cpca::SuperClusterInput input{cluster_of, triangles, k, per_pass};
        for (const cpca::NamedStrategy& s : cpca::supercluster_strategies()) {
          const auto t0 = std::chrono::steady_clock::now();
          const cpca::SuperClusters groups = cpca::group_clusters(s.name, input);
          const double seconds = seconds_since(t0);
          const cpca::OverdrawStats stats = cpca::overdraw(cluster_of, triangles, groups);
          std::printf("| %s | %d | %d | %zu | %s | %.4f | %.3f |\n", feature, k, per_pass,
                      groups.passes.size(), std::string(s.name).c_str(), stats.average_overdraw,
                      seconds);
          std::fflush(stdout);
        }
      }
    }
  }
  return 0;
}
