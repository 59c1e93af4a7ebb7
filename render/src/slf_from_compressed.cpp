#include "render/slf_from_compressed.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace render {

namespace slf_from_compressed_checks {

[[noreturn]] void refuse(const std::string& what) {
  std::string message = "surface light field from the compressed set: ";
  message += what;
  throw std::invalid_argument(message);
}

}  // namespace slf_from_compressed_checks

SlfModel slf_model_from_compressed(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                                   const prt::SlfGrid& grid, const cpca::CompressedSet& set) {
  grid.validate();
  cpca::validate_arrays(set);
  const std::size_t triangles = mesh.triangle_count();
  if (triangles == 0) slf_from_compressed_checks::refuse("the mesh has no triangles");
  if (atlas.uv.size() != 3 * triangles)
    slf_from_compressed_checks::refuse("the atlas has " + std::to_string(atlas.uv.size()) +
                                       " corner uvs for " + std::to_string(triangles) +
                                       " triangles; make the atlas from this mesh");
  if (atlas.width < 1 || atlas.height < 1)
    slf_from_compressed_checks::refuse("the atlas is " + std::to_string(atlas.width) + " x " +
                                       std::to_string(atlas.height) + " texels");
  const std::size_t texels = std::size_t(atlas.width) * std::size_t(atlas.height);
  if (atlas.texel_triangle.size() != texels)
    slf_from_compressed_checks::refuse(
        "the atlas names the triangles of " + std::to_string(atlas.texel_triangle.size()) +
        " texels; its " + std::to_string(atlas.width) + " x " + std::to_string(atlas.height) +
        " map has " + std::to_string(texels));
  std::size_t owned = 0;
  for (std::int32_t t : atlas.texel_triangle) {
    if (t < -1 || t >= std::int32_t(triangles))
      slf_from_compressed_checks::refuse("an atlas texel names triangle " + std::to_string(t) +
                                         " of " + std::to_string(triangles));
    if (t >= 0) ++owned;
  }
  if (set.vertex_count != owned)
    slf_from_compressed_checks::refuse(
        "the compressed set has " + std::to_string(set.vertex_count) + " rows; the atlas owns " +
        std::to_string(owned) + " texels (one row each, in texel order)");
  const std::size_t slice = std::size_t(grid.directions()) * 3;
  if (set.dimension() != slice)
    slf_from_compressed_checks::refuse("a compressed row holds " + std::to_string(set.dimension()) +
                                       " values; a " + std::to_string(grid.azimuth) + " x " +
                                       std::to_string(grid.elevation) +
                                       " direction grid in RGB needs " + std::to_string(slice));

  SlfModel model;
  model.positions.reserve(3 * triangles);
  model.normals.reserve(3 * triangles);
  for (std::size_t t = 0; t < triangles; ++t) {
    const meshes::Triangle& tri = mesh.triangles[t];
    for (std::uint32_t v : tri)
      if (v >= mesh.vertex_count())
        slf_from_compressed_checks::refuse("triangle " + std::to_string(t) + " names vertex " +
                                           std::to_string(v) + " of " +
                                           std::to_string(mesh.vertex_count()));
    const Eigen::Vector3f face = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                                     .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]])
                                     .normalized();
    for (std::uint32_t v : tri) {
      model.positions.push_back(mesh.positions[v]);
      model.normals.push_back(mesh.has_frames() ? mesh.normals[v] : face);
    }
  }
  model.uv = atlas.uv;
  model.map_width = atlas.width;
  model.map_height = atlas.height;
  model.grid = grid;
  model.components = set.component_count;
  model.clusters = set.cluster_count;

  const std::size_t k = std::size_t(set.component_count);
  model.texel_cluster.assign(texels, -1);
  model.texel_weights.assign(texels * k, 0.f);
  model.texel_positions = meshes::texel_points(mesh, atlas);
  if (prt::slf_grid_uses_normals(grid)) model.texel_normals = meshes::texel_normals(mesh, atlas);
  std::size_t row = 0;
  for (std::size_t t = 0; t < texels; ++t) {
    if (atlas.texel_triangle[t] < 0) continue;
    model.texel_cluster[t] = std::int32_t(set.cluster_of[row]);
    std::copy_n(set.weights.data() + row * k, k, model.texel_weights.data() + t * k);
    ++row;
  }
  model.view_maps.resize(std::size_t(model.clusters) * (k + 1) * slice);
  for (int c = 0; c < model.clusters; ++c) {
    float* out = model.view_maps.data() + std::size_t(c) * (k + 1) * slice;
    std::copy_n(set.means.data() + std::size_t(c) * slice, slice, out);
    std::copy_n(set.bases.data() + std::size_t(c) * k * slice, k * slice, out + slice);
  }
  model.validate();
  return model;
}

}  // namespace render
