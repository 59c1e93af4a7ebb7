// meshes/load.h: reading meshes from disk: OBJ and STL through OpenMesh, OFF and PLY through
// our own strict readers, glTF 2.0 (.gltf, .glb) and 3DS through Assimp behind our guards
// (docs/ARCHITECTURE.md, "Mesh assets"). A glTF or 3DS scene is flattened into world space
// through its node transforms.
//
// Loading triangulates polygons (fan), drops degenerate faces (repeated index or zero area
// after welding), welds positions closer than `weld_tolerance` times the bounding-box
// diagonal, removes vertices no face uses, and computes the per-vertex frames.
//
// Normals (docs/ARCHITECTURE.md, "Normals and creases"): a file that stores a normal for
// every vertex (OBJ vn on every face corner, glTF NORMAL, PLY nx ny nz) keeps them, and only
// vertices that share position and normal are welded. Otherwise the normals are smooth
// except across creases sharper than `crease_angle_deg`, where vertices are split
// (meshes/creases.h).
#pragma once

#include "meshes/creases.h"
#include "meshes/frames.h"
#include "meshes/mesh.h"

#include <cstddef>
#include <filesystem>
#include <string>

namespace meshes {

// The formats load_mesh reads, as command help names them.
inline constexpr const char* kMeshFormats = "OBJ, PLY, OFF, STL, glTF 2.0 (.gltf, .glb), 3DS";

struct LoadOptions {
  // Relative to the bounding-box diagonal; 0 welds only bit-identical positions, a negative
  // value disables welding.
  double weld_tolerance = 1e-6;
  NormalWeighting normal_weighting = NormalWeighting::kAngle;
  // Degrees between face normals beyond which an edge is hard, for files without normals
  // (0: all flat, 180: all smooth).
  double crease_angle_deg = kDefaultCreaseAngleDeg;
  // false: ignore the file's normals and compute them as for a file without any.
  bool file_normals = true;
};

// What loading found and changed; printed by `prtr mesh`.
struct LoadReport {
  std::string path;
  std::string format;  // lower-case extension: "obj", "ply", "off", "stl", "gltf", "glb", "3ds"
  // As the reader delivered them. Ours (OFF, PLY) deliver every record; Assimp delivers
  // glTF accessors as they are and 3DS corners unshared (three vertices per face), each
  // mesh once per node that uses it, without point and line primitives; OpenMesh's are
  // not always complete: its OBJ reader skips faces that repeat a vertex index or have fewer
  // than three corners, and its STL reader merges bit-identical corners and skips triangles
  // that repeat one. Such faces are in neither file_faces nor degenerate_faces_dropped.
  std::size_t file_vertices = 0;
  std::size_t file_faces = 0;
  std::size_t polygons_triangulated = 0;  // faces with more than three corners
  // Triangles from fan-triangulating file_faces (a k-gon gives k - 2; a face with fewer than
  // three corners counts as one degenerate triangle). Always equals the loaded mesh's
  // triangle_count() + degenerate_faces_dropped.
  std::size_t triangles_after_triangulation = 0;
  std::size_t degenerate_faces_dropped = 0;
  std::size_t vertices_welded = 0;  // vertices merged into another
  std::size_t unreferenced_vertices_dropped = 0;
  bool normals_from_file = false;
  // OBJ: vertices added because one 'v' record is used with several normals ('vn').
  std::size_t vertices_split_by_file_normals = 0;
  std::size_t vertices_split_at_creases = 0;  // meshes/creases.h, files without normals
};

// Throws MeshError whose message starts with the path and says what to do, for: a missing or
// unreadable file, a directory, an unknown extension, an empty file, content the reader
// cannot parse (including header counts the file is too small to hold, and OBJ face corners
// without a vertex number), a face naming a vertex that does not exist, NaN/Inf coordinates,
// a file too large for memory, or no faces (in the file, or left after clean-up); for glTF
// and 3DS also for what asset_guard.h refuses (claims past the data, URIs outside the file's
// folder, deep nesting) and for skins, morph targets and point/line-only scenes. Memory use
// is bounded by a constant times the file size, whatever the file claims (for glTF, whose
// nodes may reuse a mesh, also by a limit of 2^26 vertices on the flattened scene). The
// binary/ASCII decision for .stl is made by file size (84 + 50 n bytes is binary), not by
// OpenMesh's "starts with solid" test.
Mesh load_mesh(const std::filesystem::path& path, const LoadOptions& options = {},
               LoadReport* report = nullptr);

// The same clean-up load_mesh applies, for meshes built in memory: weld, drop degenerate
// and unreferenced, split creases, recompute frames (normals in `mesh` are not kept). Counts go
// into `report` when given (file_vertices and file_faces are then the mesh's counts before
// clean-up; path and format are left as they are, and a non-empty path names the mesh in errors).
// Throws MeshError for out-of-range indices, NaN/Inf positions, or no faces left.
void clean_mesh(Mesh& mesh, const LoadOptions& options = {}, LoadReport* report = nullptr);

}  // namespace meshes
