// The uncompressed path: per-vertex exit vectors e_p = M_p l' from the transfer set (CPU
// GEMMs, render/shading.h), uploaded as an SSBO; the vertex shader evaluates the SH basis.
#include "render/gl_context.h"
#include "render/shader_source.h"
#include "render_path.h"

#include <numeric>
#include <stdexcept>
#include <string>

namespace render {
namespace {

class UncompressedPath : public RenderPath {
 public:
  explicit UncompressedPath(const PathInput& in) : transfer_(*in.transfer) {
    // Mesh order: the exit vectors are indexed by gl_VertexID in source order, and
    // renumbering would cost a per-frame permutation of the whole buffer.
    std::vector<std::uint32_t> vertices(in.mesh.vertex_count());
    std::iota(vertices.begin(), vertices.end(), 0u);
    mesh_ =
        std::make_unique<GpuMesh>(in.mesh, std::move(vertices), in.options.optimize_vertex_cache);
    whole_ = mesh_->add_all_triangles();
    mesh_->upload_indices();
    const int order = transfer_.order;
    const bool glossy = transfer_.kind == prt::TransferKind::kGlossy;
    program_ = GlProgram("uncompressed shading", uncompressed_vertex_shader(order, glossy),
                         radiance_fragment_shader(), true);
    exit_buffer_ =
        make_buffer(GL_SHADER_STORAGE_BUFFER,
                    GLsizeiptr(mesh_->vertex_count() * 3 * (glossy ? order * order : 1) * 4),
                    nullptr, GL_DYNAMIC_DRAW);
    shade_whole(&program_, kExitBinding, exit_buffer_);
    in.stats.registers_per_cluster = 0;
  }
  ~UncompressedPath() override { glDeleteBuffers(1, &exit_buffer_); }

  void update(const Eigen::MatrixXd& lit, const Camera&) override {
    exit_vectors(transfer_, lit, exit_);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, exit_buffer_);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, GLsizeiptr(exit_.size() * 4), exit_.data());
  }

 private:
  const prt::TransferSet& transfer_;
  GlProgram program_;
  GLuint exit_buffer_ = 0;
  std::vector<float> exit_;
};

}  // namespace

void RenderPath::draw(const Camera& camera, const std::vector<GLuint>& queries) {
  if (!whole_program_) throw std::logic_error("a render path without draw() or shade_whole()");
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, whole_storage_.first, whole_storage_.second);
  draw_whole(*whole_program_, camera, queries);
}

std::vector<Rgb> RenderPath::capture(const Camera& camera) {
  if (!whole_program_) throw std::logic_error("a render path without capture() or shade_whole()");
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, whole_storage_.first, whole_storage_.second);
  return capture_whole(*whole_program_, camera);
}

void RenderPath::draw_whole(GlProgram& program, const Camera& camera,
                            const std::vector<GLuint>& queries) {
  set_camera_uniforms(program, camera);
  glDepthFunc(GL_LESS);
  if (!queries.empty()) glBeginQuery(GL_PRIMITIVES_GENERATED, queries[0]);
  begin_work("shade", whole_.referenced);
  mesh_->draw(whole_);
  end_work();
  if (!queries.empty()) glEndQuery(GL_PRIMITIVES_GENERATED);
}

std::vector<Rgb> RenderPath::capture_whole(GlProgram& program, const Camera& camera) {
  set_camera_uniforms(program, camera);
  std::vector<Rgb> radiance;
  mesh_->capture_points(radiance, false);
  return radiance;
}

std::unique_ptr<RenderPath> make_uncompressed_path(const PathInput& in) {
  if (!in.transfer)
    throw std::invalid_argument("uncompressed mode needs the transfer file (--transfer PRTX)");
  if (in.transfer->vertex_count != in.mesh.vertex_count())
    throw std::invalid_argument(
        "the transfer set has " + std::to_string(in.transfer->vertex_count) +
        " vertices but the mesh has " + std::to_string(in.mesh.vertex_count()) +
        "; use the mesh it was baked from");
  return std::make_unique<UncompressedPath>(in);
}

std::unique_ptr<RenderPath> make_render_path(const PathInput& in) {
  return in.options.mode == Mode::kUncompressed ? make_uncompressed_path(in)
                                                : make_cluster_path(in);
}

}  // namespace render
