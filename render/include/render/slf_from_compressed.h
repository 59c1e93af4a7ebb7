// render/slf_from_compressed.h: the renderer's surface light field (render/slf_model.h) from
// what the bake and the compression produce: the mesh, its atlas (meshes/atlas.h), the
// direction grid (prt/slf_directions.h) and the clustered PCA of the SLF matrix.
#pragma once

#include "cpca/compressed.h"
#include "meshes/atlas.h"
#include "meshes/mesh.h"
#include "prt/slf_directions.h"
#include "render/slf_model.h"

namespace render {

// `set` has one row per texel the atlas owns (texel_triangle >= 0), in texel order
// (row-major), each row the texel's radiance toward every grid direction, 3 Z W floats laid
// out as one view-map slice (column j Z + i, then RGB). Its means become slice 0 of each
// cluster's view maps, basis j slice 1 + j, its weights the surface map and cluster_of the
// texel clusters; texels no triangle owns get cluster -1 and zero weights. Corners take the
// mesh's vertex normals (the face normal where the mesh has no frames).
// Throws std::invalid_argument naming the first input whose size disagrees, then whatever
// SlfModel::validate() refuses.
SlfModel slf_model_from_compressed(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                                   const prt::SlfGrid& grid, const cpca::CompressedSet& set);

}  // namespace render
