// Chart segmentation (meshes/charts.h).
#include "meshes/charts.h"

#include "meshes/weld.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <queue>
#include <stdexcept>
#include <unordered_map>

namespace meshes {
namespace charts_cpp {

Eigen::Vector3d corner(const Mesh& mesh, const Triangle& t, int c) {
  return mesh.positions[t[c]].cast<double>();
}

Eigen::Vector3d centroid(const Mesh& mesh, int t) {
  const Triangle& tri = mesh.triangles[t];
  return (corner(mesh, tri, 0) + corner(mesh, tri, 1) + corner(mesh, tri, 2)) / 3;
}

}  // namespace charts_cpp

TriangleAdjacency triangle_adjacency(const Mesh& mesh) {
  TriangleAdjacency adj;
  const std::size_t count = mesh.triangles.size();
  adj.point = group_equal_positions(mesh.positions).group;
  adj.neighbour.assign(count, {-1, -1, -1});
  adj.degenerate.assign(count, 0);
  for (std::size_t t = 0; t < count; ++t) {
    const Triangle& tri = mesh.triangles[t];
    const std::uint32_t a = adj.point[tri[0]], b = adj.point[tri[1]], c = adj.point[tri[2]];
    const Eigen::Vector3d e1 = charts_cpp::corner(mesh, tri, 1) - charts_cpp::corner(mesh, tri, 0);
    const Eigen::Vector3d e2 = charts_cpp::corner(mesh, tri, 2) - charts_cpp::corner(mesh, tri, 0);
    const double twice = e1.cross(e2).norm();
    const double longest = std::max({e1.squaredNorm(), e2.squaredNorm(), (e2 - e1).squaredNorm()});
    adj.degenerate[t] = a == b || b == c || a == c || !(twice > 1e-10 * longest);
  }
  // Directed edges keyed by their points; an edge joins two triangles when exactly one
  // triangle runs it each way and no triangle runs it twice the same way.
  struct Half {
    int triangle, corner;
  };
  std::unordered_map<std::uint64_t, std::vector<Half>> halves;
  halves.reserve(3 * count);
  const auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t(a) << 32) | b; };
  for (std::size_t t = 0; t < count; ++t) {
    if (adj.degenerate[t]) continue;
    const Triangle& tri = mesh.triangles[t];
    for (int c = 0; c < 3; ++c)
      halves[key(adj.point[tri[c]], adj.point[tri[(c + 1) % 3]])].push_back({int(t), c});
  }
  for (const auto& [k, list] : halves) {
    if (list.size() != 1) continue;
    const std::uint32_t a = std::uint32_t(k >> 32), b = std::uint32_t(k & 0xffffffffu);
    const auto reverse = halves.find(key(b, a));
    if (reverse == halves.end() || reverse->second.size() != 1) continue;
    adj.neighbour[list[0].triangle][list[0].corner] = reverse->second[0].triangle;
  }
  return adj;
}

std::vector<int> grow_charts(const Mesh& mesh, const TriangleAdjacency& adj, double cone_degrees) {
  if (!(cone_degrees > 0 && cone_degrees < 180))
    throw std::invalid_argument("grow_charts: the normal cone must be in (0, 180) degrees, got " +
                                std::to_string(cone_degrees));
  const int count = int(mesh.triangles.size());
  const double cos_cone = std::cos(cone_degrees * std::numbers::pi / 180);
  std::vector<Eigen::Vector3d> normal(count);  // area-weighted: the cross product / 2
  for (int t = 0; t < count; ++t) {
    const Triangle& tri = mesh.triangles[t];
    normal[t] =
        0.5 * (charts_cpp::corner(mesh, tri, 1) - charts_cpp::corner(mesh, tri, 0))
                  .cross(charts_cpp::corner(mesh, tri, 2) - charts_cpp::corner(mesh, tri, 0));
    if (!normal[t].allFinite()) normal[t].setZero();
  }
  std::vector<int> chart(count, -1);
  std::vector<int> point_chart(
      adj.point.empty() ? 0 : *std::max_element(adj.point.begin(), adj.point.end()) + 1, -1);
  using Entry = std::pair<double, int>;  // (1 - cosine to the mean normal, triangle)
  int charts = 0;
  for (int seed = 0; seed < count; ++seed) {
    if (chart[seed] >= 0) continue;
    const int id = charts++;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
    const auto add = [&](int t) {
      chart[t] = id;
      mean += normal[t];
      for (int c = 0; c < 3; ++c) point_chart[adj.point[mesh.triangles[t][c]]] = id;
      const Eigen::Vector3d axis = mean.normalized();
      for (int c = 0; c < 3; ++c) {
        const int u = adj.neighbour[t][c];
        if (u < 0 || chart[u] >= 0) continue;
        const double n = normal[u].norm();
        queue.emplace(n > 0 ? 1 - normal[u].dot(axis) / n : 2.0, u);
      }
    };
    add(seed);
    if (adj.degenerate[seed]) continue;
    while (!queue.empty()) {
      const int t = queue.top().second;
      queue.pop();
      if (chart[t] >= 0) continue;
      const double n = normal[t].norm();
      if (!(n > 0) || normal[t].dot(mean.normalized()) < cos_cone * n) continue;
      int shared = 0, shared_corner = -1;
      for (int c = 0; c < 3; ++c) {
        const int u = adj.neighbour[t][c];
        if (u >= 0 && chart[u] == id) ++shared, shared_corner = c;
      }
      if (shared == 1) {
        const std::uint32_t third = adj.point[mesh.triangles[t][(shared_corner + 2) % 3]];
        if (point_chart[third] == id) continue;
      } else if (shared != 2) {
        continue;
      }
      add(t);
    }
  }
  return chart;
}

std::vector<std::vector<int>> split_chart(const Mesh& mesh, const TriangleAdjacency& adj,
                                          const std::vector<int>& triangles) {
  if (triangles.size() < 2) throw std::invalid_argument("split_chart: fewer than 2 triangles");
  std::unordered_map<int, int> local;  // mesh triangle -> index in `triangles`
  for (std::size_t i = 0; i < triangles.size(); ++i) local[triangles[i]] = int(i);
  const int n = int(triangles.size());
  std::vector<Eigen::Vector3d> centre(n);
  for (int i = 0; i < n; ++i) centre[i] = charts_cpp::centroid(mesh, triangles[i]);
  const auto farthest = [&](int from) {
    int best = from;
    double d = -1;
    for (int i = 0; i < n; ++i) {
      const double di = (centre[i] - centre[from]).squaredNorm();
      if (di > d) d = di, best = i;
    }
    return best;
  };
  const int a = farthest(0), b = farthest(a);
  // Two-source Dijkstra over the chart's adjacency.
  std::vector<double> dist(n, INFINITY);
  std::vector<int> part(n, -1);
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  dist[a] = 0, part[a] = 0, queue.emplace(0.0, a);
  if (b != a) dist[b] = 0, part[b] = 1, queue.emplace(0.0, b);
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > dist[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const int u = adj.neighbour[triangles[i]][c];
      const auto it = u >= 0 ? local.find(u) : local.end();
      if (it == local.end()) continue;
      const int j = it->second;
      const double dj = d + (centre[j] - centre[i]).norm();
      if (dj < dist[j]) dist[j] = dj, part[j] = part[i], queue.emplace(dj, j);
    }
  }
  std::vector<std::vector<int>> parts(2);
  std::vector<int> unreached;
  for (int i = 0; i < n; ++i) (part[i] >= 0 ? parts[part[i]] : unreached).push_back(triangles[i]);
  if (!unreached.empty()) {
    if (unreached.size() == 1) {
      parts.push_back(unreached);
    } else {
      // The rest is cut again (its own seeds), until every part is connected.
      for (auto& p : split_chart(mesh, adj, unreached)) parts.push_back(std::move(p));
    }
  }
  parts.erase(std::remove_if(parts.begin(), parts.end(), [](const auto& p) { return p.empty(); }),
              parts.end());
  return parts;
}

}  // namespace meshes
