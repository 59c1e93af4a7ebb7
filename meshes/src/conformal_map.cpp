// Least-squares conformal maps (meshes/conformal_map.h). In a triangle the gradient of the
// barycentric coordinate of corner j is n x e_j / (2 A), e_j the edge opposite j (from corner
// j + 1 to j + 2), so n x grad u = -sum_j u_j e_j / (2 A) and the residual of the
// Cauchy-Riemann equations is r = sum_j (v_j n x e_j + u_j e_j) / (2 A), a vector of the
// triangle's plane: two rows of the least-squares system per triangle, in any orthonormal
// basis of that plane, weighted by sqrt(A) (Lévy et al. 2002, Sec. 4.2, written with
// gradients instead of complex numbers). Pinning two vertices removes the similarities that
// leave the energy unchanged; the normal equations are solved by sparse Cholesky.
#include "meshes/conformal_map.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace meshes {
namespace conformal_map_cpp {

struct TriangleFrame {
  Eigen::Vector3d e[3];  // edges opposite each corner
  Eigen::Vector3d n;     // unit normal
  Eigen::Vector3d b1, b2;
  double area = 0;
};

bool triangle_frame(const std::vector<Eigen::Vector3d>& p, const ChartTriangle& t,
                    TriangleFrame* f) {
  for (int j = 0; j < 3; ++j) f->e[j] = p[t[(j + 2) % 3]] - p[t[(j + 1) % 3]];
  const Eigen::Vector3d cross = (p[t[1]] - p[t[0]]).cross(p[t[2]] - p[t[0]]);
  const double twice = cross.norm();
  const double longest =
      std::max({f->e[0].squaredNorm(), f->e[1].squaredNorm(), f->e[2].squaredNorm()});
  if (!(twice > 1e-12 * longest) || !std::isfinite(twice)) return false;
  f->area = 0.5 * twice;
  f->n = cross / twice;
  f->b1 = f->e[2].normalized();
  f->b2 = f->n.cross(f->b1);
  return true;
}

double signed_area(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

// Whether closed segments ab and cd meet (touching and collinear overlap included).
bool segments_meet(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const auto orient = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q,
                         const Eigen::Vector2d& r) {
    const double v = (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
    return (v > 0) - (v < 0);
  };
  const auto on = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    return std::min(p.x(), q.x()) <= r.x() && r.x() <= std::max(p.x(), q.x()) &&
           std::min(p.y(), q.y()) <= r.y() && r.y() <= std::max(p.y(), q.y());
  };
  const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && on(a, b, c)) || (o2 == 0 && on(a, b, d)) || (o3 == 0 && on(c, d, a)) ||
         (o4 == 0 && on(c, d, b));
}

}  // namespace conformal_map_cpp

std::vector<Eigen::Vector2d> conformal_map(const std::vector<Eigen::Vector3d>& positions,
                                           const std::vector<ChartTriangle>& triangles) {
  const int n = int(positions.size());
  if (n < 3 || triangles.empty()) return {};
  std::vector<char> used(n, 0);
  for (const ChartTriangle& t : triangles)
    for (int v : t) {
      if (v < 0 || v >= n) return {};
      used[v] = 1;
    }
  if (std::count(used.begin(), used.end(), 0) > 0) return {};

  // Pins: the vertex farthest from vertex 0, then the one farthest from it.
  const auto farthest = [&](int from) {
    int best = from;
    double d = -1;
    for (int v = 0; v < n; ++v) {
      const double dv = (positions[v] - positions[from]).squaredNorm();
      if (dv > d) d = dv, best = v;
    }
    return best;
  };
  const int pin_a = farthest(0), pin_b = farthest(pin_a);
  const double span = (positions[pin_b] - positions[pin_a]).norm();
  if (pin_a == pin_b || !(span > 0)) return {};
  std::vector<int> column(n, -1);  // free vertex v: u at 2 column[v], v at 2 column[v] + 1
  int free_count = 0;
  for (int v = 0; v < n; ++v)
    if (v != pin_a && v != pin_b) column[v] = free_count++;
  std::vector<Eigen::Vector2d> pinned(n, Eigen::Vector2d::Zero());
  pinned[pin_b] = Eigen::Vector2d(span, 0);

  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(triangles.size() * 12);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * std::ptrdiff_t(triangles.size()));
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const ChartTriangle& t = triangles[i];
    conformal_map_cpp::TriangleFrame f;
    if (!conformal_map_cpp::triangle_frame(positions, t, &f)) return {};
    const double scale = 1 / (2 * std::sqrt(f.area));  // sqrt(A) / (2 A)
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d cu = f.e[j] * scale, cv = f.n.cross(f.e[j]) * scale;
      const double coef[2][2] = {{cu.dot(f.b1), cv.dot(f.b1)}, {cu.dot(f.b2), cv.dot(f.b2)}};
      for (int row = 0; row < 2; ++row) {
        const int r = int(2 * i) + row;
        if (column[t[j]] >= 0) {
          entries.emplace_back(r, 2 * column[t[j]], coef[row][0]);
          entries.emplace_back(r, 2 * column[t[j]] + 1, coef[row][1]);
        } else {
          rhs[r] -= coef[row][0] * pinned[t[j]].x() + coef[row][1] * pinned[t[j]].y();
        }
      }
    }
  }
  Eigen::SparseMatrix<double> a(2 * std::ptrdiff_t(triangles.size()), 2 * free_count);
  a.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SparseMatrix<double> at = a.transpose();
  const Eigen::SparseMatrix<double> normal = at * a;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  if (solver.info() != Eigen::Success) return {};
  const Eigen::VectorXd x = solver.solve(at * rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) return {};

  std::vector<Eigen::Vector2d> uv(pinned);
  for (int v = 0; v < n; ++v)
    if (column[v] >= 0) uv[v] = Eigen::Vector2d(x[2 * column[v]], x[2 * column[v] + 1]);
  return uv;
}

double conformal_energy(const std::vector<Eigen::Vector3d>& positions,
                        const std::vector<ChartTriangle>& triangles,
                        const std::vector<Eigen::Vector2d>& uv) {
  double energy = 0, dirichlet = 0;
  for (const ChartTriangle& t : triangles) {
    conformal_map_cpp::TriangleFrame f;
    if (!conformal_map_cpp::triangle_frame(positions, t, &f)) continue;
    Eigen::Vector3d grad_u = Eigen::Vector3d::Zero(), grad_v = Eigen::Vector3d::Zero();
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d g = f.n.cross(f.e[j]) / (2 * f.area);
      grad_u += uv[t[j]].x() * g;
      grad_v += uv[t[j]].y() * g;
    }
    energy += f.area * (grad_v - f.n.cross(grad_u)).squaredNorm();
    dirichlet += f.area * (grad_u.squaredNorm() + grad_v.squaredNorm());
  }
  return dirichlet > 0 ? energy / dirichlet : 0.0;
}

bool is_embedded_disk(const std::vector<Eigen::Vector2d>& uv,
                      const std::vector<ChartTriangle>& triangles) {
  const int n = int(uv.size());
  std::unordered_map<std::uint64_t, int> directed;  // edge a -> b: how often
  const auto key = [](int a, int b) {
    return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b);
  };
  std::vector<char> used(n, 0);
  for (const ChartTriangle& t : triangles) {
    for (int v : t)
      if (v < 0 || v >= n) return false;
    if (!(conformal_map_cpp::signed_area(uv[t[0]], uv[t[1]], uv[t[2]]) > 0)) return false;
    for (int j = 0; j < 3; ++j) {
      used[t[j]] = 1;
      if (++directed[key(t[j], t[(j + 1) % 3])] > 1) return false;
    }
  }
  // Boundary edges: those whose reverse is absent. Each vertex starts at most one.
  std::vector<int> next(n, -1);
  std::vector<std::pair<int, int>> boundary;
  std::size_t undirected = 0;
  for (const auto& [k, count] : directed) {
    const int a = int(k >> 32), b = int(k & 0xffffffffu);
    if (directed.count(key(b, a))) {
      if (a < b) ++undirected;
      continue;
    }
    ++undirected;
    if (next[a] >= 0) return false;
    next[a] = b;
    boundary.emplace_back(a, b);
  }
  const std::ptrdiff_t vertices = std::count(used.begin(), used.end(), 1);
  if (vertices - std::ptrdiff_t(undirected) + std::ptrdiff_t(triangles.size()) != 1) return false;
  if (boundary.empty()) return false;
  // One loop through every boundary edge.
  std::size_t steps = 0;
  int v = boundary.front().first;
  do {
    v = next[v];
    ++steps;
  } while (v >= 0 && v != boundary.front().first && steps <= boundary.size());
  if (v != boundary.front().first || steps != boundary.size()) return false;

  // No two boundary edges meet but at their shared vertex: a uniform grid over the loop's
  // bounds, each edge tested against the edges in the cells its box covers.
  Eigen::Vector2d lo = uv[boundary.front().first], hi = lo;
  double length = 0;
  for (const auto& [a, b] : boundary) {
    lo = lo.cwiseMin(uv[a]);
    hi = hi.cwiseMax(uv[a]);
    length += (uv[b] - uv[a]).norm();
  }
  const double cell = std::max(length / double(boundary.size()), 1e-300);
  const int gx = std::clamp(int((hi.x() - lo.x()) / cell) + 1, 1, 1024);
  const int gy = std::clamp(int((hi.y() - lo.y()) / cell) + 1, 1, 1024);
  const double sx = gx / std::max(hi.x() - lo.x(), 1e-300),
               sy = gy / std::max(hi.y() - lo.y(), 1e-300);
  std::vector<std::vector<int>> grid(std::size_t(gx) * gy);
  const auto cells = [&](int e, auto&& visit) {
    const Eigen::Vector2d p = uv[boundary[e].first], q = uv[boundary[e].second];
    const int x0 = std::clamp(int((std::min(p.x(), q.x()) - lo.x()) * sx), 0, gx - 1);
    const int x1 = std::clamp(int((std::max(p.x(), q.x()) - lo.x()) * sx), 0, gx - 1);
    const int y0 = std::clamp(int((std::min(p.y(), q.y()) - lo.y()) * sy), 0, gy - 1);
    const int y1 = std::clamp(int((std::max(p.y(), q.y()) - lo.y()) * sy), 0, gy - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) visit(grid[std::size_t(y) * gx + x]);
  };
  for (int e = 0; e < int(boundary.size()); ++e) {
    bool meets = false;
    // Plain names, not a structured binding: C++17 lambdas (clang 14, the fuzz build's
    // compiler) cannot capture those.
    const int a = boundary[e].first, b = boundary[e].second;
    cells(e, [&](std::vector<int>& list) {
      for (int other : list) {
        if (meets) return;
        const auto [c, d] = boundary[other];
        if (c == a || c == b || d == a || d == b) continue;
        meets = conformal_map_cpp::segments_meet(uv[a], uv[b], uv[c], uv[d]);
      }
      list.push_back(e);
    });
    if (meets) return false;
  }
  return true;
}

}  // namespace meshes
