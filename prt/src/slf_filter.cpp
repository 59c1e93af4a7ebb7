// The texel filter (prt/slf_filter.h). Rows are filtered atlas row by atlas row, in place:
// the rows above the one being filtered are read from a ring of their originals, the rows
// below it are still original in the matrix.
#include "prt/slf_filter.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace prt {

void SlfFilterOptions::validate() const {
  if (radius < 0 || radius > 8)
    throw std::invalid_argument("--texel-filter must be in [0, 8] texels, got " +
                                std::to_string(radius));
  if (!(max_normal_degrees > 0 && max_normal_degrees <= 180))
    throw std::invalid_argument("the texel filter's normal limit must be in (0, 180] degrees");
}

void filter_slf_texels(SlfMatrix& m, const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                       const SlfFilterOptions& o) {
  o.validate();
  const std::size_t width = std::size_t(atlas.width), height = std::size_t(atlas.height);
  if (atlas.texel_triangle.size() != width * height ||
      atlas.triangle_chart.size() != mesh.triangles.size())
    throw std::invalid_argument("texel filter: the atlas was not made for this mesh");
  const std::vector<std::uint32_t> rows = slf_rows(atlas);
  if (m.shape.first_row != 0 || m.shape.row_count != rows.size() || m.shape.rows != rows.size() ||
      m.shape.atlas_width != atlas.width || m.shape.atlas_height != atlas.height)
    throw std::invalid_argument("texel filter: the matrix (" + std::to_string(m.shape.row_count) +
                                " rows) is not the whole bake on this atlas (" +
                                std::to_string(rows.size()) + " texels)");
  if (o.radius == 0 || rows.empty()) return;
  const std::size_t columns = m.shape.columns();
  const int r = o.radius;
  std::vector<std::int64_t> row_of(width * height, -1);
  for (std::size_t i = 0; i < rows.size(); ++i) row_of[rows[i]] = std::int64_t(i);
  // Each owned texel's chart and normal (the mesh's normals at the texel's barycentrics).
  std::vector<std::int32_t> chart(width * height, -1);
  std::vector<Eigen::Vector3f> normal(width * height, Eigen::Vector3f::Zero());
  for (std::uint32_t t : rows) {
    const std::int32_t tri = atlas.texel_triangle[t];
    chart[t] = atlas.triangle_chart[std::size_t(tri)];
    const meshes::Triangle& f = mesh.triangles[std::size_t(tri)];
    const Eigen::Vector2f& b = atlas.texel_barycentric[t];
    Eigen::Vector3f n;
    if (mesh.normals.size() == mesh.positions.size()) {
      n = (1 - b.x() - b.y()) * mesh.normals[f[0]] + b.x() * mesh.normals[f[1]] +
          b.y() * mesh.normals[f[2]];
    } else {
      n = (mesh.positions[f[1]] - mesh.positions[f[0]])
              .cross(mesh.positions[f[2]] - mesh.positions[f[0]]);
    }
    normal[t] = n.norm() > 0 ? Eigen::Vector3f(n.normalized()) : Eigen::Vector3f::Zero();
  }
  const float min_cos = float(std::cos(double(o.max_normal_degrees) * std::numbers::pi / 180));
  std::vector<float> spatial(std::size_t(2 * r + 1) * std::size_t(2 * r + 1));
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
      spatial[std::size_t(dy + r) * std::size_t(2 * r + 1) + std::size_t(dx + r)] =
          float(std::exp(-double(dx * dx + dy * dy) / (2.0 * r * r)));
  // Originals of the atlas rows y - r .. y - 1, slot y mod (r + 1), by x.
  std::vector<float> ring(std::size_t(r + 1) * width * columns);
  std::vector<float> out(width * columns);
  const auto original = [&](std::size_t x, std::size_t y, std::size_t now) -> const float* {
    if (y >= now) return m.data.data() + std::size_t(row_of[y * width + x]) * columns;
    return ring.data() + ((y % std::size_t(r + 1)) * width + x) * columns;
  };
  for (std::size_t y = 0; y < height; ++y) {
    tbb::parallel_for(std::size_t(0), width, [&](std::size_t x) {
      const std::size_t t = y * width + x;
      if (row_of[t] < 0) return;
      float* o_row = out.data() + x * columns;
      std::fill(o_row, o_row + columns, 0.f);
      double total = 0;
      for (int dy = -r; dy <= r; ++dy) {
        const std::int64_t ny = std::int64_t(y) + dy;
        if (ny < 0 || ny >= std::int64_t(height)) continue;
        for (int dx = -r; dx <= r; ++dx) {
          const std::int64_t nx = std::int64_t(x) + dx;
          if (nx < 0 || nx >= std::int64_t(width)) continue;
          const std::size_t n = std::size_t(ny) * width + std::size_t(nx);
          // The texel itself always counts, even with a degenerate (zero) normal.
          if (n != t &&
              (row_of[n] < 0 || chart[n] != chart[t] || normal[n].dot(normal[t]) < min_cos))
            continue;
          const float w =
              spatial[std::size_t(dy + r) * std::size_t(2 * r + 1) + std::size_t(dx + r)];
          const float* in = original(std::size_t(nx), std::size_t(ny), y);
          for (std::size_t c = 0; c < columns; ++c) o_row[c] += w * in[c];
          total += w;
        }
      }
      const float scale = float(1.0 / total);
      for (std::size_t c = 0; c < columns; ++c) o_row[c] *= scale;
    });
    float* slot = ring.data() + (y % std::size_t(r + 1)) * width * columns;
    for (std::size_t x = 0; x < width; ++x) {
      if (row_of[y * width + x] < 0) continue;
      float* row = m.data.data() + std::size_t(row_of[y * width + x]) * columns;
      std::copy_n(row, columns, slot + x * columns);
      std::copy_n(out.data() + x * columns, columns, row);
    }
  }
}

}  // namespace prt
