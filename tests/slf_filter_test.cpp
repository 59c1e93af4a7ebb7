// Tests for prt/slf_filter.h: a constant matrix stays constant; on a flat plane the filter
// divides independent noise's variance by sum(w)^2 / sum(w^2) of its Gaussian weights (the
// analytic figure for a weighted mean) wherever its whole window lies on the chart; texels
// of different charts never mix; a normal limit below the mesh's turn between texels leaves
// the matrix nearly as it was, and a texel without a normal keeps its value; radius 0
// changes nothing; bad options and a partial matrix are refused.
#include "prt/slf_filter.h"

#include "meshes/atlas.h"
#include "meshes/frames.h"
#include "meshes/procedural.h"
#include "prt/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace {

// A matrix of the atlas's owned texels with `columns` / 3 directions, each entry f(row, column).
template <class F>
prt::SlfMatrix matrix_on(const meshes::Atlas& atlas, int directions, F f) {
  prt::SlfMatrix m;
  m.shape.atlas_width = atlas.width;
  m.shape.atlas_height = atlas.height;
  m.shape.charts = atlas.charts;
  m.shape.grid = {directions, 1};
  m.shape.rows = m.shape.row_count = prt::slf_rows(atlas).size();
  m.data.resize(m.shape.row_count * m.shape.columns());
  for (std::size_t r = 0; r < m.shape.row_count; ++r)
    for (std::size_t c = 0; c < m.shape.columns(); ++c) m.data[r * m.shape.columns() + c] = f(r, c);
  return m;
}

TEST(SlfFilter, ConstantStaysConstant) {
  meshes::Mesh mesh = meshes::make_sphere(1.f, 24, 12);
  const meshes::Atlas atlas = meshes::make_atlas(mesh, 96, 96);
  prt::SlfMatrix m = matrix_on(atlas, 4, [](std::size_t, std::size_t c) { return 0.5f + c; });
  prt::filter_slf_texels(m, mesh, atlas, {2, 20.f});
  for (std::size_t i = 0; i < m.data.size(); ++i)
    ASSERT_NEAR(m.data[i], 0.5f + float(i % m.shape.columns()), 1e-5f) << i;
}

TEST(SlfFilter, NoiseFallsAsAWeightedMeanPredicts) {
  const meshes::Mesh mesh = meshes::make_plane(4.f, 8);
  const meshes::Atlas atlas = meshes::make_atlas(mesh, 128, 128);
  ASSERT_EQ(atlas.chart_count, 1);
  prt::Pcg32 rng(5);
  // Uniform noise in [-1, 1): variance 1/3 before.
  prt::SlfMatrix m = matrix_on(
      atlas, 8, [&](std::size_t, std::size_t) { return float(2 * rng.next_double() - 1); });
  const std::vector<float> before = m.data;
  for (const int radius : {1, 2}) {
    m.data = before;
    prt::filter_slf_texels(m, mesh, atlas, {radius, 20.f});
    double sum = 0, sum2 = 0;
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        const double w = std::exp(-double(dx * dx + dy * dy) / (2.0 * radius * radius));
        sum += w, sum2 += w * w;
      }
    const std::vector<std::uint32_t> rows = prt::slf_rows(atlas);
    std::vector<std::int64_t> row_of(std::size_t(atlas.width) * atlas.height, -1);
    for (std::size_t r = 0; r < rows.size(); ++r) row_of[rows[r]] = std::int64_t(r);
    double variance = 0;
    std::size_t count = 0;
    for (int y = radius; y < atlas.height - radius; ++y)
      for (int x = radius; x < atlas.width - radius; ++x) {
        bool inside = true;
        for (int dy = -radius; dy <= radius && inside; ++dy)
          for (int dx = -radius; dx <= radius && inside; ++dx)
            inside = row_of[std::size_t(y + dy) * atlas.width + std::size_t(x + dx)] >= 0;
        if (!inside) continue;
        const std::size_t r = std::size_t(row_of[std::size_t(y) * atlas.width + std::size_t(x)]);
        for (std::size_t c = 0; c < m.shape.columns(); ++c) {
          variance += std::pow(double(m.data[r * m.shape.columns() + c]), 2);
          ++count;
        }
      }
    ASSERT_GT(count, 100000u);
    // Neighbouring outputs share inputs, so the estimate's own spread is some percent.
    EXPECT_NEAR(variance / double(count) / (1.0 / 3.0), sum2 / (sum * sum),
                0.05 * sum2 / (sum * sum))
        << radius;
  }
}

TEST(SlfFilter, ChartsDoNotMix) {
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 12, 6);
  const meshes::Atlas atlas =
      meshes::make_atlas(mesh, 128, 128, {meshes::AtlasCharts::kPerTriangle});
  ASSERT_GT(atlas.chart_count, 50);
  const std::vector<std::uint32_t> rows = prt::slf_rows(atlas);
  const auto chart_of_row = [&](std::size_t r) {
    return float(atlas.triangle_chart[std::size_t(atlas.texel_triangle[rows[r]])]);
  };
  prt::SlfMatrix m =
      matrix_on(atlas, 2, [&](std::size_t r, std::size_t) { return chart_of_row(r); });
  prt::filter_slf_texels(m, mesh, atlas, {3, 180.f});
  for (std::size_t r = 0; r < rows.size(); ++r)
    ASSERT_NEAR(m.data[r * m.shape.columns()], chart_of_row(r), 1e-3f) << r;
}

TEST(SlfFilter, TheNormalLimitKeepsTurningTexelsApart) {
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 24, 12);
  const meshes::Atlas atlas = meshes::make_atlas(mesh, 96, 96);
  prt::Pcg32 rng(6);
  prt::SlfMatrix m =
      matrix_on(atlas, 2, [&](std::size_t, std::size_t) { return float(rng.next_double()); });
  const std::vector<float> before = m.data;
  const auto changed = [&](float degrees) {
    m.data = before;
    prt::filter_slf_texels(m, mesh, atlas, {2, degrees});
    std::size_t n = 0;
    for (std::size_t i = 0; i < m.data.size(); ++i) n += m.data[i] != before[i];
    return double(n) / double(m.data.size());
  };
  // A texel of this atlas turns about 2 degrees from the next: at 0.01 degrees only texels
  // that sample the same normal (gutter texels at a chart's corner take its nearest point)
  // still mix; at 20 degrees nearly all do.
  const double tight = changed(0.01f), loose = changed(20.f);
  EXPECT_GT(loose, 0.95);
  EXPECT_LT(tight, 0.5 * loose);
  // A texel with no normal (a degenerate mesh) keeps its own value rather than none.
  meshes::Mesh flat = mesh;
  for (meshes::Vec3& n : flat.normals) n = meshes::Vec3::Zero();
  m.data = before;
  prt::filter_slf_texels(m, flat, atlas, {2, 20.f});
  EXPECT_EQ(m.data, before);
  // Radius 0 is no filter.
  m.data = before;
  prt::filter_slf_texels(m, mesh, atlas, {0, 20.f});
  EXPECT_EQ(m.data, before);
}

TEST(SlfFilter, BadOptionsAndPartialMatricesAreRefused) {
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 12, 6);
  const meshes::Atlas atlas = meshes::make_atlas(mesh, 64, 64);
  prt::SlfMatrix m = matrix_on(atlas, 2, [](std::size_t, std::size_t) { return 1.f; });
  EXPECT_THROW(prt::filter_slf_texels(m, mesh, atlas, {9, 20.f}), std::invalid_argument);
  EXPECT_THROW(prt::filter_slf_texels(m, mesh, atlas, {-1, 20.f}), std::invalid_argument);
  EXPECT_THROW(prt::filter_slf_texels(m, mesh, atlas, {1, 0.f}), std::invalid_argument);
  EXPECT_THROW(prt::filter_slf_texels(m, mesh, atlas, {1, std::nanf("")}), std::invalid_argument);
  prt::SlfMatrix part = m;
  part.shape.first_row = 1;
  part.shape.row_count -= 1;
  part.data.resize(part.shape.row_count * part.shape.columns());
  EXPECT_THROW(prt::filter_slf_texels(part, mesh, atlas, {1, 20.f}), std::invalid_argument);
  const meshes::Atlas other = meshes::make_atlas(mesh, 48, 48);
  EXPECT_THROW(prt::filter_slf_texels(m, mesh, other, {1, 20.f}), std::invalid_argument);
}

}  // namespace
