// render/src/gpu_mesh.h (private): a mesh on the GPU in a render path's vertex order, shared
// by every path: positions, normals and tangents, a radiance buffer (what transform feedback
// writes and the pass-through shader reads), optional per-vertex cluster data, and index
// ranges (the whole mesh, or one per pass), each in vertex-cache order.
#pragma once

#include "gl_program.h"
#include "meshes/mesh.h"
#include "render/camera.h"
#include "render/shading.h"

#include <cstdint>
#include <vector>

namespace render {

struct IndexRange {
  GLsizeiptr first = 0;  // in indices
  GLsizei count = 0;
  std::uint64_t referenced = 0;  // distinct vertices the range's indices name
};

GLuint make_buffer(GLenum target, GLsizeiptr bytes, const void* data, GLenum usage);

// Uses `program` and sets the camera uniforms every mesh shader declares.
void set_camera_uniforms(GlProgram& program, const Camera& camera);

// Each source vertex's position in the order the (cache-ordered, when `optimize`) triangle
// list first uses it; unreferenced vertices last. llvmpipe reuses a shaded vertex only while
// its index is still in a small direct-mapped cache keyed by the index value, so vertices
// numbered in first-use order rarely collide (docs/ARCHITECTURE.md "Rendering", Vertex reuse).
std::vector<std::uint32_t> first_use_rank(const meshes::Mesh& mesh, bool optimize);

// Appends to `old_of_new` one block of copies of the vertices `triangle_ids` reference, in
// first-use order after cache ordering (when `optimize`), and returns the block's index list
// in GPU numbering: a draw over it names consecutive, collision-free indices.
std::vector<std::uint32_t> append_vertex_block(const meshes::Mesh& source,
                                               const std::vector<std::uint32_t>& triangle_ids,
                                               bool optimize,
                                               std::vector<std::uint32_t>& old_of_new);

// The corners of `triangle_ids`, three per triangle, in vertex-cache order when `optimize`
// (source numbering).
std::vector<std::uint32_t> triangle_corners(const meshes::Mesh& source,
                                            const std::vector<std::uint32_t>& triangle_ids,
                                            bool optimize);

class GpuMesh {
 public:
  // `old_of_new[i]` is the source vertex stored at GPU vertex i. Its first
  // source.vertex_count() entries are a permutation (the numbering of mesh() and of the whole
  // mesh's triangles); any further entries are copies (per-pass blocks, append_vertex_block).
  GpuMesh(const meshes::Mesh& source, std::vector<std::uint32_t> old_of_new,
          bool optimize_vertex_cache);
  ~GpuMesh();
  GpuMesh(const GpuMesh&) = delete;
  GpuMesh& operator=(const GpuMesh&) = delete;

  const meshes::Mesh& mesh() const { return mesh_; }  // in GPU vertex order
  const std::vector<std::uint32_t>& old_of_new() const { return old_of_new_; }
  std::size_t vertex_count() const { return old_of_new_.size(); }  // with copies
  std::size_t source_vertex_count() const { return source_vertices_; }

  // One index range of the source triangles `ids`; upload_indices() after the last one.
  IndexRange add_triangles(const std::vector<std::uint32_t>& ids);
  IndexRange add_all_triangles();
  // A ready index list in GPU numbering (append_vertex_block's), kept in its order.
  IndexRange add_indices(const std::vector<std::uint32_t>& list);
  void upload_indices();

  void uint_attribute(GLuint location, const std::vector<std::uint32_t>& values);
  // `components` floats per vertex, padded to vec4 attributes from kAttrWeights on; the
  // attributes are enabled only when `enable` (paths that shade on the CPU do not read them).
  void weight_attributes(const std::vector<float>& weights, int components, bool enable);

  void bind() const { glBindVertexArray(vao_); }
  void draw(const IndexRange& range) const;
  GLuint radiance_buffer() const { return radiance_; }

  // Per-vertex RGB of `buffer` (after glFinish), added to or replacing `into`.
  void read(GLuint buffer, std::vector<Rgb>& into, bool add) const;
  // Draws every vertex once as a point with the current program and captures v_radiance.
  void capture_points(std::vector<Rgb>& into, bool add) const;

 private:
  meshes::Mesh mesh_;
  std::vector<std::uint32_t> old_of_new_;
  std::size_t source_vertices_ = 0;
  bool optimize_ = true;
  GLuint vao_ = 0, radiance_ = 0, capture_ = 0, ibo_ = 0;
  std::vector<GLuint> buffers_;
  std::vector<std::uint32_t> indices_;
};

}  // namespace render
