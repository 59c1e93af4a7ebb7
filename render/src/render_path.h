// render/src/render_path.h (private): one class per rendering path (render/renderer.h lists
// them) behind one interface. The Renderer owns what every path shares (SH rotation, the
// framebuffer, the background, primitive queries); a path owns its GPU mesh, programs and
// buffers and knows only how to update its per-frame data, draw, and capture its vertex
// stage's output.
#pragma once

#include "gpu_mesh.h"
#include "render/renderer.h"
#include "work_counter.h"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace render {

class RenderPath {
 public:
  virtual ~RenderPath() = default;

  const GpuMesh& mesh() const { return *mesh_; }

  // Per frame, before draw or capture: whatever the path derives from the rotated lighting
  // l' (n x 3), computed and uploaded.
  virtual void update(const Eigen::MatrixXd& lit, const Camera& camera) = 0;
  // Draws the mesh into the bound, cleared framebuffer (depth test and culling set); with
  // `queries` (one per pass()), counts each pass's primitives. By default: one draw of the
  // program given to shade_whole().
  virtual void draw(const Camera& camera, const std::vector<GLuint>& queries);
  // A depth pre-pass that draw() relies on, if the path has one (none by default): drawn
  // right before draw(), into the same state.
  virtual void draw_depth(const Camera&) {}
  // The per-vertex radiance the vertex stage produces, in GPU vertex order. By default: the
  // program given to shade_whole(), run over every vertex once.
  virtual std::vector<Rgb> capture(const Camera& camera);

  // Shading passes that draw triangles, and whether pass p drew any (an empty pass has no
  // query result).
  virtual std::size_t passes() const { return 1; }
  virtual bool pass_drew(std::size_t) const { return true; }

  // Where draw() counts its work; null (the default) counts nothing.
  void set_work_counter(WorkCounter* counter) { work_ = counter; }

 protected:
  void begin_work(std::string label, std::uint64_t referenced) {
    if (work_) work_->begin(std::move(label), referenced);
  }
  void end_work() {
    if (work_) work_->end();
  }

  // For a path that shades in one draw of `program`, which reads `buffer` at shader storage
  // binding `binding`: the default draw() and capture() then serve it.
  void shade_whole(GlProgram* program, GLuint binding, GLuint buffer) {
    whole_program_ = program;
    whole_storage_ = {binding, buffer};
  }

  // One draw of the whole mesh with `program` (depth test GL_LESS), counted in queries[0].
  void draw_whole(GlProgram& program, const Camera& camera, const std::vector<GLuint>& queries);
  // Every vertex through `program` once, as points, capturing its radiance.
  std::vector<Rgb> capture_whole(GlProgram& program, const Camera& camera);

  std::unique_ptr<GpuMesh> mesh_;
  IndexRange whole_;
  WorkCounter* work_ = nullptr;

 private:
  GlProgram* whole_program_ = nullptr;
  std::pair<GLuint, GLuint> whole_storage_{0, 0};  // binding, buffer
};

struct PathInput {
  const meshes::Mesh& mesh;
  const cpca::CompressedSet* set;
  const prt::TransferSet* transfer;
  const RendererOptions& options;
  RenderStats& stats;  // the path fills what it decides (budget, passes, overdraw)
};

// The path of options.mode; std::invalid_argument for inputs the path cannot use.
std::unique_ptr<RenderPath> make_render_path(const PathInput& input);

// The paths, one per file group (cluster_paths.cpp, uncompressed_path.cpp).
std::unique_ptr<RenderPath> make_cluster_path(const PathInput& input);
std::unique_ptr<RenderPath> make_uncompressed_path(const PathInput& input);

}  // namespace render
