// meshes/atlas.cpp: per-triangle charts paired into square cells and shelf-packed, after
// Carr & Hart, "Meshed atlases for real-time procedural solid texturing" (ACM TOG 21, 2002):
// every triangle is mapped affinely onto a right isosceles triangle, and two of them share a
// square cell, one in its lower-left corner and one (turned by 180 degrees) in its
// upper-right corner, with a gap along the diagonal. Unlike their uniform cells, a chart's
// legs follow the triangle's area (legs k sqrt(2 area), so a chart covers k^2 area texels),
// with the scale k found by bisection as the largest that still packs.
//
// Coordinates below are in texels, and a cell of S x S texels holds its charts as
// meshes/src/atlas_detail.h says, so cells can touch. Along the diagonal, lookups of the lower
// chart (x + y <= c) read texels with i + j <= floor(c) + 1, those of the upper one
// (x + y >= c') texels with i + j > c' - 3; c' - c >= 4 keeps them apart, i.e.
// a + b <= 2 S - 6 - 4 d for legs a and b.
#include "meshes/atlas.h"

#include "atlas_detail.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace meshes {
namespace {

using atlas_detail::kInset;
using atlas_detail::kMaxSize;
using atlas_detail::nearest_weights;

// One chart: a right isosceles triangle with its right angle at `corner`, legs `leg` long
// along +-x and +-y (sign: +1 for a lower-left chart, -1 for an upper-right one).
struct Chart {
  Eigen::Vector2d corner = Eigen::Vector2d::Zero();
  double leg = 0;
  int sign = 1;
  int right = 0;  // the mesh corner mapped to the right angle
};

struct Cell {
  int first = -1, second = -1;  // triangles; second -1 for a lone last one
  int side = 0;                 // S: the cell's texels X .. X + S - 1
  int x = 0, y = 0;
};

// Chart corner c (0: right angle, 1: along x, 2: along y) in texel coordinates.
Eigen::Vector2d chart_point(const Chart& chart, int c) {
  Eigen::Vector2d p = chart.corner;
  if (c == 1) p.x() += chart.sign * chart.leg;
  if (c == 2) p.y() += chart.sign * chart.leg;
  return p;
}

// Whether a lookup at some point of the chart reads texel (i, j): whether the chart meets
// [i - 0.5, i + 1.5) x [j - 0.5, j + 1.5).
bool chart_reads(const Chart& chart, int i, int j) {
  const double l = i - 0.5, r = i + 1.5, m = j - 0.5, t = j + 1.5;
  const double x0 = chart.corner.x(), y0 = chart.corner.y();
  if (chart.sign > 0) {
    // {x >= x0, y >= y0, x + y <= x0 + y0 + leg}: the box's lowest feasible corner decides.
    const double x = std::max(x0, l), y = std::max(y0, m);
    return x < r && y < t && x + y <= x0 + y0 + chart.leg;
  }
  // {x <= x0, y <= y0, x + y >= x0 + y0 - leg}: the box's highest feasible point decides; the
  // box is open at r and t, so a supremum there is not reached.
  if (l > x0 || m > y0) return false;
  const double x = std::min(x0, r), y = std::min(y0, t);
  const bool open = r <= x0 || t <= y0;
  const double c = x0 + y0 - chart.leg;
  return open ? x + y > c : x + y >= c;
}

// The mesh corner with the largest angle goes to the right angle (least distortion).
int widest_corner(const Mesh& mesh, const Triangle& t) {
  int best = 0;
  double best_cos = 2;
  for (int c = 0; c < 3; ++c) {
    const Eigen::Vector3d p = mesh.positions[t[c]].cast<double>();
    const Eigen::Vector3d e1 = mesh.positions[t[(c + 1) % 3]].cast<double>() - p;
    const Eigen::Vector3d e2 = mesh.positions[t[(c + 2) % 3]].cast<double>() - p;
    const double n = e1.norm() * e2.norm();
    const double cosine = n > 0 ? e1.dot(e2) / n : 1;
    if (cosine < best_cos) {
      best_cos = cosine;
      best = c;
    }
  }
  return best;
}

// Legs at scale k for the area-sorted triangles, paired into cells; false when they do not
// fit width x height. Cells are shelf-packed in order (their sides never grow along it).
bool pack(const std::vector<int>& order, const std::vector<double>& legs_unit, double k, int width,
          int height, std::vector<Cell>* cells) {
  std::vector<Cell> out;
  out.reserve((order.size() + 1) / 2);
  int x = 0, y = 0, shelf = 0;
  for (std::size_t i = 0; i < order.size(); i += 2) {
    Cell cell;
    cell.first = order[i];
    cell.second = i + 1 < order.size() ? order[i + 1] : -1;
    const double a = k * legs_unit[cell.first];
    const double b = cell.second >= 0 ? k * legs_unit[cell.second] : 0.0;
    // A leg must end before the last texel centre but one (a + d < S - 1, its lookups then
    // stay in the cell), and the diagonal gap needs a + b <= 2 S - 6 - 4 d.
    const double side =
        std::max({a + 1 + 2 * kInset, b + 1 + 2 * kInset, 0.5 * (a + b + 6 + 4 * kInset)});
    if (!(side < kMaxSize)) return false;
    cell.side = int(std::ceil(side));
    const int pitch = cell.side;
    if (x + pitch > width) {
      x = 0;
      y += shelf;
      shelf = 0;
    }
    if (x + pitch > width || y + pitch > height) return false;
    cell.x = x;
    cell.y = y;
    x += pitch;
    shelf = std::max(shelf, pitch);
    out.push_back(cell);
  }
  if (cells) *cells = std::move(out);
  return true;
}

// Per-triangle charts.
Atlas make_per_triangle_atlas(const Mesh& mesh, int width, int height);

}  // namespace

// The point of triangle (a, b, c) nearest to p, as weights of a, b and c (Ericson,
// "Real-Time Collision Detection", 5.1.5, by Voronoi regions).
Eigen::Vector3d atlas_detail::nearest_weights(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                              const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a, ac = c - a, ap = p - a;
  // A triangle flattened to a segment (or a point) has no inside: its nearest point is on
  // one of its edges (the Voronoi regions below assume a proper triangle).
  const double longest = std::max({ab.squaredNorm(), ac.squaredNorm(), (c - b).squaredNorm()});
  if (!(std::abs(ab.x() * ac.y() - ab.y() * ac.x()) > 1e-12 * longest)) {
    const Eigen::Vector2d* q[3] = {&a, &b, &c};
    Eigen::Vector3d best(1, 0, 0);
    double best_distance = INFINITY;
    for (int e = 0; e < 3; ++e) {
      const int i = e, j = (e + 1) % 3;
      const Eigen::Vector2d d = *q[j] - *q[i];
      const double length = d.squaredNorm();
      const double t = length > 0 ? std::clamp((p - *q[i]).dot(d) / length, 0.0, 1.0) : 0.0;
      const double distance = (*q[i] + t * d - p).squaredNorm();
      if (distance < best_distance) {
        best_distance = distance;
        best.setZero();
        best[i] = 1 - t;
        best[j] = t;
      }
    }
    return best;
  }
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Eigen::Vector2d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return {1 - v, v, 0};
  }
  const Eigen::Vector2d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return {1 - w, 0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - w, w};
  }
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return {1 - v - w, v, w};
}

void atlas_detail::check_atlas_input(const Mesh& mesh, int width, int height) {
  using atlas_detail::kMinSize;
  for (const auto& [name, value] : {std::pair{"width", width}, std::pair{"height", height}}) {
    if (value < kMinSize || value > kMaxSize) {
      throw std::invalid_argument(std::string("atlas ") + name + " must be in [" +
                                  std::to_string(kMinSize) + ", " + std::to_string(kMaxSize) +
                                  "] texels, got " + std::to_string(value));
    }
  }
  if (mesh.triangles.empty()) throw std::invalid_argument("make_atlas: the mesh has no triangles");
}

std::size_t Atlas::used_texels() const {
  return std::size_t(std::count_if(texel_triangle.begin(), texel_triangle.end(),
                                   [](std::int32_t t) { return t >= 0; }));
}

namespace {

// Per texel, `at(triangle, barycentrics)`; zero where no triangle reads it. `what` names the
// caller in messages.
template <typename At>
std::vector<Eigen::Vector3f> per_texel(const Mesh& mesh, const Atlas& atlas, const char* what,
                                       const At& at) {
  const std::size_t texels = std::size_t(atlas.width) * std::size_t(atlas.height);
  if (atlas.texel_triangle.size() != texels || atlas.texel_barycentric.size() != texels)
    throw std::invalid_argument(std::string(what) + ": the atlas names the triangles of " +
                                std::to_string(atlas.texel_triangle.size()) +
                                " and the points of " +
                                std::to_string(atlas.texel_barycentric.size()) + " texels; its " +
                                std::to_string(atlas.width) + " x " + std::to_string(atlas.height) +
                                " map has " + std::to_string(texels));
  std::vector<Eigen::Vector3f> values(texels, Eigen::Vector3f::Zero());
  for (std::size_t t = 0; t < texels; ++t) {
    const std::int32_t triangle = atlas.texel_triangle[t];
    if (triangle < 0) continue;
    if (std::size_t(triangle) >= mesh.triangle_count())
      throw std::invalid_argument(std::string(what) + ": texel " + std::to_string(t) +
                                  " names triangle " + std::to_string(triangle) + " of " +
                                  std::to_string(mesh.triangle_count()));
    values[t] = at(mesh.triangles[std::size_t(triangle)], atlas.texel_barycentric[t]);
  }
  return values;
}

}  // namespace

std::vector<Eigen::Vector3f> texel_points(const Mesh& mesh, const Atlas& atlas) {
  return per_texel(mesh, atlas, "texel points", [&](const Triangle& tri, const Eigen::Vector2f& b) {
    return Eigen::Vector3f((1.f - b.x() - b.y()) * mesh.positions[tri[0]] +
                           b.x() * mesh.positions[tri[1]] + b.y() * mesh.positions[tri[2]]);
  });
}

std::vector<Eigen::Vector3f> texel_normals(const Mesh& mesh, const Atlas& atlas) {
  return per_texel(
      mesh, atlas, "texel normals", [&](const Triangle& tri, const Eigen::Vector2f& b) {
        if (mesh.has_frames()) {
          const Eigen::Vector3f n = (1.f - b.x() - b.y()) * mesh.normals[tri[0]] +
                                    b.x() * mesh.normals[tri[1]] + b.y() * mesh.normals[tri[2]];
          if (n.norm() > 1e-6f) return Eigen::Vector3f(n.normalized());
        }
        const Eigen::Vector3f face = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                                         .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]]);
        return face.norm() > 0.f ? Eigen::Vector3f(face.normalized()) : Eigen::Vector3f::UnitY();
      });
}

Atlas make_atlas(const Mesh& mesh, int width, int height, const AtlasOptions& options) {
  atlas_detail::check_atlas_input(mesh, width, height);
  switch (options.charts) {
    case AtlasCharts::kPerTriangle:
      return make_per_triangle_atlas(mesh, width, height);
    case AtlasCharts::kConformal:
      return atlas_detail::make_conformal_atlas(mesh, width, height);
  }
  throw std::invalid_argument("make_atlas: unknown chart method " +
                              std::to_string(std::uint32_t(options.charts)));
}

namespace {

Atlas make_per_triangle_atlas(const Mesh& mesh, int width, int height) {
  const int count = int(mesh.triangles.size());
  std::vector<double> legs_unit(count);  // leg at k = 1: the chart's area equals the triangle's
  double total_area = 0;
  for (int t = 0; t < count; ++t) {
    const double area = 0.5 * double(double_area(mesh, mesh.triangles[t]));
    legs_unit[t] = std::isfinite(area) ? std::sqrt(2 * area) : 0.0;
    total_area += legs_unit[t] * legs_unit[t] / 2;
  }
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return legs_unit[a] > legs_unit[b]; });

  if (!pack(order, legs_unit, 0.0, width, height, nullptr)) {
    throw std::invalid_argument(
        "a " + std::to_string(width) + " x " + std::to_string(height) +
        " atlas is too small to give each of the mesh's " + std::to_string(count) +
        " triangles a chart (two per cell of at least 4 x 4 texels, about " +
        std::to_string(8 * std::size_t(count)) + " texels); use a larger atlas");
  }
  // The interior area alone bounds k: k^2 total_area <= width height.
  double lo = 0, hi = total_area > 0 ? std::sqrt(double(width) * height / total_area) : 0.0;
  if (hi > 0 && pack(order, legs_unit, hi, width, height, nullptr)) lo = hi;
  for (int it = 0; it < 50 && hi - lo > 1e-9 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (pack(order, legs_unit, mid, width, height, nullptr) ? lo : hi) = mid;
  }
  std::vector<Cell> cells;
  pack(order, legs_unit, lo, width, height, &cells);

  Atlas atlas;
  atlas.charts = AtlasCharts::kPerTriangle;
  atlas.width = width;
  atlas.height = height;
  atlas.uv.assign(3 * std::size_t(count), Eigen::Vector2f::Zero());
  atlas.texel_triangle.assign(std::size_t(width) * height, -1);
  atlas.texel_barycentric.assign(std::size_t(width) * height, Eigen::Vector2f::Zero());
  atlas.triangle_chart.resize(count);
  std::iota(atlas.triangle_chart.begin(), atlas.triangle_chart.end(), 0);
  atlas.chart_count = count;

  auto place = [&](int t, const Chart& chart) {
    Eigen::Vector2d q[3];  // chart points of mesh corners 0, 1, 2
    for (int c = 0; c < 3; ++c) {
      q[(chart.right + c) % 3] = chart_point(chart, c);
    }
    for (int c = 0; c < 3; ++c) {
      atlas.uv[3 * std::size_t(t) + c] =
          Eigen::Vector2f(float(q[c].x() / width), float(q[c].y() / height));
    }
    // Texels the chart's lookups can read: within one texel and a half of its bounds.
    const double lo_x = std::min({q[0].x(), q[1].x(), q[2].x()});
    const double hi_x = std::max({q[0].x(), q[1].x(), q[2].x()});
    const double lo_y = std::min({q[0].y(), q[1].y(), q[2].y()});
    const double hi_y = std::max({q[0].y(), q[1].y(), q[2].y()});
    const int i0 = std::max(0, int(std::floor(lo_x - 0.5)));
    const int i1 = std::min(width - 1, int(std::floor(hi_x - 0.5)) + 1);
    const int j0 = std::max(0, int(std::floor(lo_y - 0.5)));
    const int j1 = std::min(height - 1, int(std::floor(hi_y - 0.5)) + 1);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        if (!chart_reads(chart, i, j)) continue;
        const std::size_t at = std::size_t(j) * width + i;
        if (atlas.texel_triangle[at] >= 0) {
          throw std::logic_error("make_atlas: texel (" + std::to_string(i) + ", " +
                                 std::to_string(j) + ") is read by two charts");
        }
        atlas.texel_triangle[at] = t;
        Eigen::Vector3d w = nearest_weights(Eigen::Vector2d(i + 0.5, j + 0.5), q[0], q[1], q[2]);
        w = w.cwiseMax(0.0);  // rounding can leave -1e-17 outside the triangle
        w /= w.sum();
        atlas.texel_barycentric[at] = Eigen::Vector2f(float(w[1]), float(w[2]));
      }
    }
  };
  for (const Cell& cell : cells) {
    Chart first;
    first.corner = Eigen::Vector2d(cell.x + 0.5 + kInset, cell.y + 0.5 + kInset);
    first.leg = lo * legs_unit[cell.first];
    first.sign = 1;
    first.right = widest_corner(mesh, mesh.triangles[cell.first]);
    place(cell.first, first);
    if (cell.second < 0) continue;
    Chart second;
    second.corner =
        Eigen::Vector2d(cell.x + cell.side - 0.5 - kInset, cell.y + cell.side - 0.5 - kInset);
    second.leg = lo * legs_unit[cell.second];
    second.sign = -1;
    second.right = widest_corner(mesh, mesh.triangles[cell.second]);
    place(cell.second, second);
  }
  return atlas;
}

}  // namespace
}  // namespace meshes
