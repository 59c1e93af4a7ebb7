// The conformal atlas (meshes/atlas.h): charts grown over the surface (meshes/charts.h),
// flattened by least-squares conformal maps (meshes/conformal_map.h), checked, each scaled so
// its texture area equals its surface area, turned to its smallest bounding box, and packed
// at the largest common scale that fits (Lévy et al., "Least Squares Conformal Maps for
// Automatic Texture Atlas Generation", SIGGRAPH 2002, Secs. 3-5).
//
// A chart is accepted when its map is an embedded disk and its area stretch, sqrt(texture
// area / surface area) per triangle at the chart's own scale, stays within [1/2, 2]: the
// atlas samples the surface uniformly up to that factor in texel spacing. A chart that fails
// is cut in two (meshes::split_chart) and each part tried again; a single triangle is laid
// flat by its own edge lengths (isometric, also for degenerate triangles).
//
// Each chart has a cell of S_x x S_y texels (the rule of meshes/src/atlas_detail.h: lookups
// from inside it read only the cell's texels). A texel is read by the chart when the chart
// meets the square its lookups come from, [i - 0.5, i + 1.5] x [j - 0.5, j + 1.5], widened
// by a thousandth of a texel so that float texture coordinates rounded across the square's
// edge still read owned texels. Packing keeps the read texels of different charts apart
// (cells may overlap where the charts do not read), so a texel belongs to one chart and
// samples that chart's point nearest its centre (the point mapped to the centre, inside it).
//
// A chart can still be an embedded disk whose boundary runs back alongside itself (around a
// notch, or where it curls round an ear): texels between the two sides are read from both,
// yet the sides are far apart on the surface. After filling, every chart whose lookups read
// a texel sampling a point more than kNearTexels texel widths (in 3D) from the lookup is
// cut in two and everything packed again, for up to kMaxRounds rounds; then whatever is
// still cut goes flat triangle by triangle.
#include "atlas_detail.h"

#include "meshes/charts.h"
#include "meshes/conformal_map.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace meshes {
namespace atlas_conformal_cpp {

constexpr double kConeDegrees = 65;
constexpr double kMaxStretch = 2;  // per-triangle sqrt(area ratio), either way
constexpr double kReadSlack = 1e-3;
// A lookup may read a texel sampling a point this many texel widths away in 3D: lookup and
// texel centre are within sqrt(2) texels, the centre and its sample too, and a chart's
// stretch of up to 2 makes 2 x 2 sqrt(2) = 5.7 in the worst case.
constexpr double kNearTexels = 6;
constexpr int kMaxRounds = 12;

// A chart laid out at unit density (texture area = surface area), in its bounding box's
// frame: corners in [0, width] x [0, height].
struct Layout {
  std::vector<int> triangles;            // mesh triangles
  std::vector<Eigen::Vector2d> corners;  // 3 per triangle, mesh corner order
  double width = 0, height = 0;
};

struct Placed {
  int x = 0, y = 0;            // where the turned cell's texel (0, 0) goes
  int side_x = 0, side_y = 0;  // the cell before it is turned
  int turns = 0;               // quarter turns (turn())
};

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

Layout flat_triangle(const Mesh& mesh, int t) {
  const Triangle& tri = mesh.triangles[t];
  const Eigen::Vector3d p0 = mesh.positions[tri[0]].cast<double>();
  const Eigen::Vector3d e1 = mesh.positions[tri[1]].cast<double>() - p0;
  const Eigen::Vector3d e2 = mesh.positions[tri[2]].cast<double>() - p0;
  Layout layout;
  layout.triangles = {t};
  Eigen::Vector2d q1 = Eigen::Vector2d::Zero(), q2 = Eigen::Vector2d::Zero();
  const double l1 = e1.norm();
  if (l1 > 0 && std::isfinite(l1)) {
    const Eigen::Vector3d x = e1 / l1;
    const double along = e2.dot(x);
    q1 = Eigen::Vector2d(l1, 0);
    q2 = Eigen::Vector2d(along, (e2 - along * x).norm());
  } else if (const double l2 = e2.norm(); l2 > 0 && std::isfinite(l2)) {
    q2 = Eigen::Vector2d(l2, 0);
  }
  layout.corners = {Eigen::Vector2d::Zero(), q1, q2};
  return layout;
}

// The chart's map, scaled to unit density, or false when it is not an acceptable chart.
bool conformal_layout(const Mesh& mesh, const TriangleAdjacency& adj,
                      const std::vector<int>& triangles, Layout* layout) {
  std::unordered_map<std::uint32_t, int> local;  // point -> chart vertex
  std::vector<Eigen::Vector3d> positions;
  std::vector<ChartTriangle> chart_triangles;
  chart_triangles.reserve(triangles.size());
  for (int t : triangles) {
    if (adj.degenerate[t]) return false;
    ChartTriangle ct;
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = mesh.triangles[t][c];
      const auto [it, added] = local.emplace(adj.point[v], int(positions.size()));
      if (added) positions.push_back(mesh.positions[v].cast<double>());
      ct[c] = it->second;
    }
    chart_triangles.push_back(ct);
  }
  const std::vector<Eigen::Vector2d> uv = conformal_map(positions, chart_triangles);
  if (uv.empty() || !is_embedded_disk(uv, chart_triangles)) return false;
  double surface = 0, texture = 0;
  std::vector<double> ratio(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const ChartTriangle& ct = chart_triangles[i];
    const double a3 =
        0.5 *
        (positions[ct[1]] - positions[ct[0]]).cross(positions[ct[2]] - positions[ct[0]]).norm();
    const double a2 = 0.5 * cross2(uv[ct[1]] - uv[ct[0]], uv[ct[2]] - uv[ct[0]]);
    surface += a3;
    texture += a2;
    ratio[i] = a2 / a3;
  }
  if (!(surface > 0 && texture > 0)) return false;
  const double scale = std::sqrt(surface / texture);
  for (double r : ratio) {
    const double stretch = scale * std::sqrt(r);
    if (!(stretch <= kMaxStretch && stretch >= 1 / kMaxStretch)) return false;
  }
  layout->triangles = triangles;
  layout->corners.resize(3 * triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (int c = 0; c < 3; ++c) layout->corners[3 * i + c] = scale * uv[chart_triangles[i][c]];
  return true;
}

// Turns the layout to the smallest-area bounding box of its convex hull (one side along a
// hull edge, Freeman & Shapira's theorem), wider than tall, and moves it to the origin.
void fit_box(Layout* layout) {
  std::vector<Eigen::Vector2d> points = layout->corners;
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  std::vector<Eigen::Vector2d> hull;  // Andrew's monotone chain
  if (points.size() >= 3) {
    hull.resize(2 * points.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      while (k >= 2 && cross2(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
      hull[k++] = points[i];
    }
    for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
      while (k >= lower && cross2(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0) --k;
      hull[k++] = points[i];
    }
    hull.resize(k - 1);
  } else {
    hull = points;
  }
  Eigen::Vector2d best_axis(1, 0);
  double best_area = INFINITY;
  for (std::size_t i = 0; i < hull.size(); ++i) {
    Eigen::Vector2d axis = hull[(i + 1) % hull.size()] - hull[i];
    if (!(axis.norm() > 0)) continue;
    axis.normalize();
    double lo_x = INFINITY, hi_x = -INFINITY, lo_y = INFINITY, hi_y = -INFINITY;
    for (const Eigen::Vector2d& p : hull) {
      const double x = p.dot(axis), y = cross2(axis, p);
      lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x);
      lo_y = std::min(lo_y, y), hi_y = std::max(hi_y, y);
    }
    const double area = (hi_x - lo_x) * (hi_y - lo_y);
    if (area < best_area) best_area = area, best_axis = axis;
  }
  // Rotation taking best_axis to +x; a quarter turn more when taller than wide.
  Eigen::Matrix2d turn;
  turn << best_axis.x(), best_axis.y(), -best_axis.y(), best_axis.x();
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  for (Eigen::Vector2d& p : layout->corners) {
    p = turn * p;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (layout->corners.empty()) lo = hi = Eigen::Vector2d::Zero();
  const bool quarter = hi.y() - lo.y() > hi.x() - lo.x();
  for (Eigen::Vector2d& p : layout->corners) {
    p -= lo;
    if (quarter) p = Eigen::Vector2d(hi.y() - lo.y() - p.y(), p.x());
  }
  layout->width = quarter ? hi.y() - lo.y() : hi.x() - lo.x();
  layout->height = quarter ? hi.x() - lo.x() : hi.y() - lo.y();
}

// Whether the triangle meets the axis-aligned box [lo, hi] (separating axes: the box's two
// and the triangle's edge normals; a degenerate triangle's zero normals separate nothing).
bool triangle_meets_box(const Eigen::Vector2d q[3], const Eigen::Vector2d& lo,
                        const Eigen::Vector2d& hi) {
  for (int axis = 0; axis < 2; ++axis) {
    const double mn = std::min({q[0][axis], q[1][axis], q[2][axis]});
    const double mx = std::max({q[0][axis], q[1][axis], q[2][axis]});
    if (mx < lo[axis] || mn > hi[axis]) return false;
  }
  const Eigen::Vector2d box[4] = {lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}};
  for (int e = 0; e < 3; ++e) {
    const Eigen::Vector2d d = q[(e + 1) % 3] - q[e];
    const Eigen::Vector2d n(-d.y(), d.x());
    double t_lo = INFINITY, t_hi = -INFINITY, b_lo = INFINITY, b_hi = -INFINITY;
    for (int c = 0; c < 3; ++c) {
      const double v = n.dot(q[c]);
      t_lo = std::min(t_lo, v), t_hi = std::max(t_hi, v);
    }
    for (const Eigen::Vector2d& p : box) {
      const double v = n.dot(p);
      b_lo = std::min(b_lo, v), b_hi = std::max(b_hi, v);
    }
    if (t_hi < b_lo || t_lo > b_hi) return false;
  }
  return true;
}

// The part of the triangle inside the box [lo, hi] (Sutherland-Hodgman), as a polygon.
std::vector<Eigen::Vector2d> clip_to_box(const Eigen::Vector2d q[3], const Eigen::Vector2d& lo,
                                         const Eigen::Vector2d& hi) {
  std::vector<Eigen::Vector2d> poly(q, q + 3), next;
  for (int side = 0; side < 4 && !poly.empty(); ++side) {
    const int axis = side / 2;
    const double bound = side % 2 ? hi[axis] : lo[axis];
    const auto inside = [&](const Eigen::Vector2d& p) {
      return side % 2 ? p[axis] <= bound : p[axis] >= bound;
    };
    next.clear();
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const Eigen::Vector2d& a = poly[k];
      const Eigen::Vector2d& b = poly[(k + 1) % poly.size()];
      if (inside(a)) next.push_back(a);
      if (inside(a) != inside(b)) {
        const double t = (bound - a[axis]) / (b[axis] - a[axis]);
        next.push_back(a + t * (b - a));
      }
    }
    poly.swap(next);
  }
  return poly;
}

// A chart in its cell at scale k: local cell coordinates c = (0.5 + d) + k corner, cell
// S_x x S_y. Turned by quarter turns about the cell (rotations, so triangles keep their
// orientation): 1: (S_y - c_y, c_x), 2: (S_x - c_x, S_y - c_y), 3: (c_y, S_x - c_x). A turned
// cell reads texel (i', j') exactly where the unturned one reads the texel it maps back to,
// since the read squares [i - 0.5, i + 1.5] map onto each other.
Eigen::Vector2d turn(const Eigen::Vector2d& c, int turns, int side_x, int side_y) {
  switch (turns) {
    case 1:
      return {side_y - c.y(), c.x()};
    case 2:
      return {side_x - c.x(), side_y - c.y()};
    case 3:
      return {c.y(), side_x - c.x()};
    default:
      return c;
  }
}

// The texels a chart's lookups read in its cell at scale k, as spans: per column the lowest
// and highest row, per row the leftmost and rightmost column. Texel (i, j) is read when a
// triangle meets [i - 0.5, i + 1.5] x [j - 0.5, j + 1.5] (widened by the slack), so a column's
// rows follow from the y-range of each triangle clipped to the column's slab (its whole
// y-range for a triangle within two columns, a little more than exact). Texels between two
// read ones of a span count as read: a notch is not filled by another chart.
struct Profile {
  int side_x = 0, side_y = 0;
  std::vector<int> column_lo, column_hi;  // per column; lo > hi when it is not read
  std::vector<int> row_lo, row_hi;        // per row
};

void add_spans(const Eigen::Vector2d q[3], int axis, int side_along, int side_across,
               std::vector<int>& lo, std::vector<int>& hi) {
  const int other = 1 - axis;
  const double mn = std::min({q[0][axis], q[1][axis], q[2][axis]});
  const double mx = std::max({q[0][axis], q[1][axis], q[2][axis]});
  const int i0 = std::max(0, int(std::ceil(mn - 1.5 - kReadSlack)));
  const int i1 = std::min(side_along - 1, int(std::floor(mx + 0.5 + kReadSlack)));
  const double whole_lo = std::min({q[0][other], q[1][other], q[2][other]});
  const double whole_hi = std::max({q[0][other], q[1][other], q[2][other]});
  for (int i = i0; i <= i1; ++i) {
    double y0 = whole_lo, y1 = whole_hi;
    if (i1 - i0 > 2) {
      Eigen::Vector2d box_lo = Eigen::Vector2d::Constant(-INFINITY), box_hi = -box_lo;
      box_lo[axis] = i - 0.5 - kReadSlack;
      box_hi[axis] = i + 1.5 + kReadSlack;
      const std::vector<Eigen::Vector2d> part = clip_to_box(q, box_lo, box_hi);
      if (part.empty()) continue;
      y0 = INFINITY, y1 = -INFINITY;
      for (const Eigen::Vector2d& v : part)
        y0 = std::min(y0, v[other]), y1 = std::max(y1, v[other]);
    }
    lo[i] = std::min(lo[i], std::max(0, int(std::ceil(y0 - 1.5 - kReadSlack))));
    hi[i] = std::max(hi[i], std::min(side_across - 1, int(std::floor(y1 + 0.5 + kReadSlack))));
  }
}

Profile profile_of(const Layout& layout, double k) {
  Profile p;
  p.side_x = int(std::ceil(k * layout.width + 1 + 2 * atlas_detail::kInset));
  p.side_y = int(std::ceil(k * layout.height + 1 + 2 * atlas_detail::kInset));
  p.column_lo.assign(p.side_x, p.side_y);
  p.column_hi.assign(p.side_x, -1);
  p.row_lo.assign(p.side_y, p.side_x);
  p.row_hi.assign(p.side_y, -1);
  const Eigen::Vector2d origin = Eigen::Vector2d::Constant(0.5 + atlas_detail::kInset);
  for (std::size_t t = 0; t < layout.triangles.size(); ++t) {
    Eigen::Vector2d q[3];
    for (int m = 0; m < 3; ++m) q[m] = origin + k * layout.corners[3 * t + m];
    add_spans(q, 0, p.side_x, p.side_y, p.column_lo, p.column_hi);
    add_spans(q, 1, p.side_y, p.side_x, p.row_lo, p.row_hi);
  }
  return p;
}

// The column spans of the chart turned `turns` quarter turns (turn() above): column i of
// the turned cell is a row or column of the unturned one, its span mirrored as the turn says.
void turned_columns(const Profile& p, int turns, std::vector<int>& lo, std::vector<int>& hi) {
  const int width = turns % 2 ? p.side_y : p.side_x;
  lo.resize(width);
  hi.resize(width);
  for (int i = 0; i < width; ++i) {
    int a = 0, b = 0;
    switch (turns) {
      case 1:  // column i is row S_y - 1 - i; rows are columns
        a = p.row_lo[p.side_y - 1 - i], b = p.row_hi[p.side_y - 1 - i];
        break;
      case 2:  // column i is column S_x - 1 - i, rows mirrored
        a = p.side_y - 1 - p.column_hi[p.side_x - 1 - i];
        b = p.side_y - 1 - p.column_lo[p.side_x - 1 - i];
        break;
      case 3:  // column i is row i; rows are mirrored columns
        a = p.side_x - 1 - p.row_hi[i], b = p.side_x - 1 - p.row_lo[i];
        break;
      default:
        a = p.column_lo[i], b = p.column_hi[i];
    }
    lo[i] = a, hi[i] = b;
  }
}

// Skyline packing of the charts' spans (after the Tetris packing of Lévy et al. 2002,
// Sec. 5): each chart, in order, in each of its four quarter turns, goes where its top ends
// lowest above the atlas's current horizon (then where it wastes the fewest texels between
// the horizon and its lower edge), and raises the horizon to its upper edge. Charts' read
// texels never meet, so their cells may overlap.
bool pack_skyline(const std::vector<Layout>& layouts, const std::vector<int>& order, double k,
                  int width, int height, std::vector<Placed>* placed) {
  if (placed) placed->assign(layouts.size(), Placed{});
  std::vector<int> horizon(width, 0), lo, hi;
  for (int c : order) {
    const double sx = k * layouts[c].width + 1 + 2 * atlas_detail::kInset;
    const double sy = k * layouts[c].height + 1 + 2 * atlas_detail::kInset;
    if (!(sx < std::max(width, height) + 1) || !(sy < std::max(width, height) + 1)) return false;
    const Profile p = profile_of(layouts[c], k);
    Placed best;
    long long best_waste = 0, best_top = 0;
    bool found = false;
    for (int turns = 0; turns < 4; ++turns) {
      turned_columns(p, turns, lo, hi);
      const int side = int(lo.size());
      for (int x = 0; x + side <= width; ++x) {
        int y = INT_MIN;
        for (int i = 0; i < side; ++i)
          if (lo[i] <= hi[i]) y = std::max(y, horizon[x + i] - lo[i]);
        if (y == INT_MIN) y = 0;
        long long waste = 0, top = 0;
        for (int i = 0; i < side; ++i) {
          if (lo[i] > hi[i]) continue;
          waste += y + lo[i] - horizon[x + i];
          top = std::max<long long>(top, y + hi[i]);
        }
        if (top >= height) continue;
        if (!found || top < best_top || (top == best_top && waste < best_waste)) {
          found = true;
          best = Placed{x, y, p.side_x, p.side_y, turns};
          best_waste = waste, best_top = top;
        }
      }
    }
    if (!found) return false;
    turned_columns(p, best.turns, lo, hi);
    for (int i = 0; i < int(lo.size()); ++i)
      if (lo[i] <= hi[i]) horizon[best.x + i] = best.y + hi[i] + 1;
    if (placed) (*placed)[c] = best;
  }
  return true;
}

// Weights of a, b and c giving p (the triangle is not degenerate).
Eigen::Vector3d barycentric(const Eigen::Vector2d& p, const Eigen::Vector2d q[3]) {
  const Eigen::Vector2d e1 = q[1] - q[0], e2 = q[2] - q[0], d = p - q[0];
  const double det = cross2(e1, e2);
  const double u = cross2(d, e2) / det, v = cross2(e1, d) / det;
  return {1 - u - v, u, v};
}

Eigen::Vector3d on_surface(const Mesh& mesh, int t, const Eigen::Vector3d& w) {
  const Triangle& tri = mesh.triangles[t];
  return w[0] * mesh.positions[tri[0]].cast<double>() +
         w[1] * mesh.positions[tri[1]].cast<double>() +
         w[2] * mesh.positions[tri[2]].cast<double>();
}

struct Filled {
  Atlas atlas;
  std::vector<int> far;  // charts where a lookup reads a texel sampling a far point
};

// Places the layouts at scale k in their cells and fills the texels. A chart whose lookups
// read a texel sampling a point farther than kNearTexels texel widths (at the atlas's
// density, 1 / k) from the lookup's own point is reported: two parts of its boundary run
// side by side in the texture but not on the surface, so texels between them mix the two.
Filled fill_texels(const Mesh& mesh, const std::vector<Layout>& layouts,
                   const std::vector<Placed>& cells, double k, int width, int height) {
  Filled out;
  Atlas& atlas = out.atlas;
  const int charts = int(layouts.size());
  atlas.charts = AtlasCharts::kConformal;
  atlas.width = width;
  atlas.height = height;
  atlas.uv.assign(3 * mesh.triangles.size(), Eigen::Vector2f::Zero());
  atlas.texel_triangle.assign(std::size_t(width) * height, -1);
  atlas.texel_barycentric.assign(std::size_t(width) * height, Eigen::Vector2f::Zero());
  atlas.triangle_chart.assign(mesh.triangles.size(), -1);
  atlas.chart_count = charts;

  struct Best {
    double distance = INFINITY;
    int triangle = -1;
    Eigen::Vector3d weights = Eigen::Vector3d::Zero();
    bool read = false;
  };
  std::vector<Best> best;
  const Eigen::Vector2d slack = Eigen::Vector2d::Constant(kReadSlack);
  const double far = kNearTexels / k;
  for (int c = 0; c < charts; ++c) {
    const Layout& layout = layouts[c];
    const Placed& placed = cells[c];
    // The turned cell: its texels x .. x + side_x - 1, y .. y + side_y - 1.
    const bool quarter = placed.turns % 2 == 1;
    const Placed cell{placed.x, placed.y, quarter ? placed.side_y : placed.side_x,
                      quarter ? placed.side_x : placed.side_y, 0};
    const Eigen::Vector2d origin = Eigen::Vector2d::Constant(0.5 + atlas_detail::kInset);
    best.assign(std::size_t(cell.side_x) * cell.side_y, Best{});
    const auto corners = [&](std::size_t i, Eigen::Vector2d q[3]) {
      for (int m = 0; m < 3; ++m) {
        q[m] = Eigen::Vector2d(cell.x, cell.y) + turn(origin + k * layout.corners[3 * i + m],
                                                      placed.turns, placed.side_x, placed.side_y);
      }
    };
    // Texels whose centres lie within 2 texels of the triangle's box: any nearer point of
    // the chart to a texel the chart reads lies within sqrt(2) of its centre.
    const auto range = [&](const Eigen::Vector2d q[3], int axis, int first, int side) {
      const double mn = std::min({q[0][axis], q[1][axis], q[2][axis]});
      const double mx = std::max({q[0][axis], q[1][axis], q[2][axis]});
      return std::pair{std::max(first, int(std::floor(mn - 2.5))),
                       std::min(first + side - 1, int(std::ceil(mx + 1.5)))};
    };
    for (std::size_t i = 0; i < layout.triangles.size(); ++i) {
      const int t = layout.triangles[i];
      atlas.triangle_chart[t] = c;
      Eigen::Vector2d q[3];
      corners(i, q);
      for (int m = 0; m < 3; ++m) {
        atlas.uv[3 * std::size_t(t) + m] =
            Eigen::Vector2f(float(q[m].x() / width), float(q[m].y() / height));
      }
      const auto [i0, i1] = range(q, 0, cell.x, cell.side_x);
      const auto [j0, j1] = range(q, 1, cell.y, cell.side_y);
      for (int j = j0; j <= j1; ++j) {
        for (int x = i0; x <= i1; ++x) {
          Best& b = best[std::size_t(j - cell.y) * cell.side_x + (x - cell.x)];
          const Eigen::Vector2d centre(x + 0.5, j + 0.5);
          const Eigen::Vector3d w = atlas_detail::nearest_weights(centre, q[0], q[1], q[2]);
          const double d = (w[0] * q[0] + w[1] * q[1] + w[2] * q[2] - centre).squaredNorm();
          if (d < b.distance) b.distance = d, b.triangle = t, b.weights = w;
          if (!b.read) {
            b.read = triangle_meets_box(q, Eigen::Vector2d(x - 0.5, j - 0.5) - slack,
                                        Eigen::Vector2d(x + 1.5, j + 1.5) + slack);
          }
        }
      }
    }
    for (int j = 0; j < cell.side_y; ++j) {
      for (int x = 0; x < cell.side_x; ++x) {
        Best& b = best[std::size_t(j) * cell.side_x + x];
        if (!b.read) continue;
        if (cell.x + x < 0 || cell.x + x >= width || cell.y + j < 0 || cell.y + j >= height) {
          throw std::logic_error("make_atlas: a chart reads texel (" + std::to_string(cell.x + x) +
                                 ", " + std::to_string(cell.y + j) + ") outside the atlas");
        }
        const std::size_t at = std::size_t(cell.y + j) * width + (cell.x + x);
        if (atlas.texel_triangle[at] >= 0) {
          throw std::logic_error("make_atlas: texel (" + std::to_string(cell.x + x) + ", " +
                                 std::to_string(cell.y + j) + ") is read by two charts");
        }
        b.weights = b.weights.cwiseMax(0.0);  // rounding can leave -1e-17 outside
        b.weights /= b.weights.sum();
        atlas.texel_triangle[at] = b.triangle;
        atlas.texel_barycentric[at] = Eigen::Vector2f(float(b.weights[1]), float(b.weights[2]));
      }
    }
    if (layout.triangles.size() == 1) continue;  // a flat triangle: every point is near
    // The farthest lookup point reading a texel is a vertex of the triangle clipped to the
    // square of lookups that read it (distance is convex).
    bool near = true;
    for (std::size_t i = 0; i < layout.triangles.size() && near; ++i) {
      const int t = layout.triangles[i];
      Eigen::Vector2d q[3];
      corners(i, q);
      const auto [i0, i1] = range(q, 0, cell.x, cell.side_x);
      const auto [j0, j1] = range(q, 1, cell.y, cell.side_y);
      for (int j = j0; j <= j1 && near; ++j) {
        for (int x = i0; x <= i1 && near; ++x) {
          const Best& b = best[std::size_t(j - cell.y) * cell.side_x + (x - cell.x)];
          if (!b.read) continue;
          const std::vector<Eigen::Vector2d> part =
              clip_to_box(q, Eigen::Vector2d(x - 0.5, j - 0.5) - slack,
                          Eigen::Vector2d(x + 1.5, j + 1.5) + slack);
          if (part.empty()) continue;
          const Eigen::Vector3d sample = on_surface(mesh, b.triangle, b.weights);
          for (const Eigen::Vector2d& p : part) {
            if ((on_surface(mesh, t, barycentric(p, q)) - sample).norm() > far) near = false;
          }
        }
      }
    }
    if (!near) out.far.push_back(c);
  }
  return out;
}

}  // namespace atlas_conformal_cpp

Atlas atlas_detail::make_conformal_atlas(const Mesh& mesh, int width, int height) {
  namespace impl = atlas_conformal_cpp;
  const TriangleAdjacency adj = triangle_adjacency(mesh);
  const std::vector<int> grown = grow_charts(mesh, adj, impl::kConeDegrees);
  const int grown_count = grown.empty() ? 0 : *std::max_element(grown.begin(), grown.end()) + 1;
  std::vector<std::vector<int>> pending(grown_count);
  for (int t = 0; t < int(grown.size()); ++t) pending[grown[t]].push_back(t);
  std::reverse(pending.begin(), pending.end());  // taken from the back: in seed order

  std::vector<impl::Layout> layouts;
  for (int round = 0;; ++round) {
    while (!pending.empty()) {
      std::vector<int> triangles = std::move(pending.back());
      pending.pop_back();
      impl::Layout layout;
      // After a few rounds of cutting charts whose lookups still mix far points, their
      // triangles go flat one by one, which always succeeds.
      if (triangles.size() == 1 || round >= impl::kMaxRounds) {
        for (int t : triangles) {
          layout = impl::flat_triangle(mesh, t);
          impl::fit_box(&layout);
          layouts.push_back(std::move(layout));
        }
        continue;
      }
      if (!impl::conformal_layout(mesh, adj, triangles, &layout)) {
        std::vector<std::vector<int>> parts = split_chart(mesh, adj, triangles);
        for (auto it = parts.rbegin(); it != parts.rend(); ++it) pending.push_back(std::move(*it));
        continue;
      }
      impl::fit_box(&layout);
      layouts.push_back(std::move(layout));
    }

    const int charts = int(layouts.size());
    std::vector<int> order(charts);
    std::iota(order.begin(), order.end(), 0);
    // Largest bounding box first, the small ones fill the gaps the large ones leave.
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return layouts[a].width * layouts[a].height > layouts[b].width * layouts[b].height;
    });
    if (!impl::pack_skyline(layouts, order, 0.0, width, height, nullptr)) {
      throw std::invalid_argument(
          "a " + std::to_string(width) + " x " + std::to_string(height) +
          " atlas is too small to hold the mesh's " + std::to_string(charts) +
          " charts (a cell of at least 2 x 2 texels each); use a larger atlas");
    }
    double surface = 0;
    for (const impl::Layout& layout : layouts)
      for (std::size_t i = 0; i < layout.triangles.size(); ++i)
        surface += 0.5 * std::abs(impl::cross2(layout.corners[3 * i + 1] - layout.corners[3 * i],
                                               layout.corners[3 * i + 2] - layout.corners[3 * i]));
    // The charts' area alone bounds the scale: k^2 surface <= width height.
    double lo = 0, hi = surface > 0 ? std::sqrt(double(width) * height / surface) : 0.0;
    if (hi > 0 && impl::pack_skyline(layouts, order, hi, width, height, nullptr)) lo = hi;
    for (int it = 0; it < 40 && hi - lo > 1e-4 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      (impl::pack_skyline(layouts, order, mid, width, height, nullptr) ? lo : hi) = mid;
    }
    std::vector<impl::Placed> cells;
    impl::pack_skyline(layouts, order, lo, width, height, &cells);
    impl::Filled filled = impl::fill_texels(mesh, layouts, cells, lo, width, height);
    if (filled.far.empty()) return std::move(filled.atlas);
    // Cut the charts that mix far points and pack again (their cells change the scale).
    std::vector<char> cut(layouts.size(), 0);
    for (int c : filled.far) cut[c] = 1;
    std::vector<impl::Layout> kept;
    for (int c = 0; c < charts; ++c) {
      if (!cut[c]) {
        kept.push_back(std::move(layouts[c]));
        continue;
      }
      for (auto& part : split_chart(mesh, adj, layouts[c].triangles))
        pending.push_back(std::move(part));
    }
    layouts = std::move(kept);
  }
}

}  // namespace meshes
