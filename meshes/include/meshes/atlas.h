// meshes/atlas.h: a texture atlas that samples the surface uniformly by area, for the surface
// light field (SLF paper, Sec. 3.1: "uniform sampling of the spatial dimension", so the
// number of samples does not depend on the vertex count).
//
// The surface is cut into charts, each mapped one-to-one into its own part of the atlas, so
// texture coordinates are per corner. Two ways to cut it (AtlasCharts):
//  - per triangle: every triangle is its own chart (at least 8 texels a triangle, so the
//    texel count grows with the triangle count);
//  - conformal (the default): charts of many triangles (meshes/charts.h), each flattened by a
//    least-squares conformal map (meshes/conformal_map.h) and scaled so its texture area
//    follows its surface area; a chart that does not flatten one-to-one, whose area stretch
//    is too uneven, or whose lookups read texels sampling far-away points of itself (two
//    stretches of its boundary side by side in the texture) is cut again, down to single
//    triangles if need be.
// A texel belongs to at most one chart: the one whose bilinear lookups read it. It samples
// the point of that chart that maps to its centre, and a texel around a chart (its gutter)
// the chart's nearest point, so a bilinear lookup anywhere inside a chart reads only texels
// of that chart, sampling points near the lookup's (inside a chart the map is continuous).
#pragma once

#include "common/enum_names.h"
#include "meshes/mesh.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace meshes {

enum class AtlasCharts : std::uint32_t {
  kPerTriangle = 0,  // Carr & Hart's meshed atlas; what .slf/.slfc files of version 1 used
  kConformal = 1,
};
inline constexpr auto kAtlasChartsNames = common::enum_table<AtlasCharts>(
    "atlas charts",
    {{AtlasCharts::kPerTriangle, "per-triangle"}, {AtlasCharts::kConformal, "conformal"}});

struct AtlasOptions {
  AtlasCharts charts = AtlasCharts::kConformal;
};

struct Atlas {
  AtlasCharts charts = AtlasCharts::kConformal;  // how it was cut (files record it)
  int width = 0, height = 0;                     // texels
  std::vector<Eigen::Vector2f> uv{};  // 3 per triangle (corner 3 t + i), in [0, 1]^2; texel
                                      // x's centre is at (x + 0.5) / width
  // Per texel, row-major (y * width + x): the triangle whose lookups read it (-1: none) and
  // the barycentrics (u, v) of the surface point it samples, p = (1-u-v) p0 + u p1 + v p2.
  std::vector<std::int32_t> texel_triangle{};
  std::vector<Eigen::Vector2f> texel_barycentric{};
  // Per triangle, its chart (0 .. chart_count - 1); per triangle: the triangle itself.
  std::vector<std::int32_t> triangle_chart{};
  int chart_count = 0;

  std::size_t used_texels() const;
};

// Per texel, the surface point it samples (its triangle at its barycentrics); (0, 0, 0) where
// no triangle reads it. `mesh` is the one the atlas was made from (std::invalid_argument
// when the sizes say otherwise).
std::vector<Eigen::Vector3f> texel_points(const Mesh& mesh, const Atlas& atlas);
// Per texel, the unit shading normal there: the vertex normals interpolated and normalised,
// the face's where the mesh has none or they cancel (prt::PathTracer::surface_point's rule);
// (0, 0, 0) where no triangle reads it.
std::vector<Eigen::Vector3f> texel_normals(const Mesh& mesh, const Atlas& atlas);

// An atlas of at most width x height texels, the same for the same mesh and options. Throws
// std::invalid_argument when the size is out of range or too small to hold every chart.
Atlas make_atlas(const Mesh& mesh, int width, int height, const AtlasOptions& options = {});

}  // namespace meshes
