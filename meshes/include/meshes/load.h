// meshes/load.h: reading meshes from disk through OpenMesh (OBJ, PLY, OFF, STL).
//
// Loading triangulates polygons (fan), drops degenerate faces (repeated index or zero area
// after welding), welds positions closer than `weld_tolerance` times the bounding-box
// diagonal, removes vertices no face uses, and computes the per-vertex frames.
#pragma once

#include "meshes/frames.h"
#include "meshes/mesh.h"

#include <cstddef>
#include <filesystem>
#include <string>

namespace meshes {

struct LoadOptions {
  // Relative to the bounding-box diagonal; 0 welds only bit-identical positions, a negative
  // value disables welding.
  double weld_tolerance = 1e-6;
  NormalWeighting normal_weighting = NormalWeighting::kAngle;
};

// What loading found and changed; printed by `prtr mesh`.
struct LoadReport {
  std::string path;
  std::string format;  // lower-case extension: "obj", "ply", "off", "stl"
  std::size_t file_vertices = 0;
  std::size_t file_faces = 0;
  std::size_t polygons_triangulated = 0;  // faces with more than three corners
  std::size_t degenerate_faces_dropped = 0;
  std::size_t vertices_welded = 0;        // vertices merged into another
  std::size_t unreferenced_vertices_dropped = 0;
};

// Throws MeshError naming the path for: a missing or unreadable file, an unknown extension,
// an empty file, no faces left, or NaN/Inf coordinates.
Mesh load_mesh(const std::filesystem::path& path, const LoadOptions& options = {},
               LoadReport* report = nullptr);

// The same clean-up load_mesh applies, for meshes built in memory: weld, drop degenerate
// and unreferenced, recompute frames. Counts go into `report` when given.
void clean_mesh(Mesh& mesh, const LoadOptions& options = {}, LoadReport* report = nullptr);

}  // namespace meshes
