#include "render/renderer.h"

#include "background_pass.h"
#include "common/enum_names.h"
#include "frame_target.h"
#include "median.h"
#include "prt/sh_rotation.h"
#include "render/gl_context.h"
#include "render_path.h"
#include "work_counter.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace render {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

// What every path shares: the SH rotation, the framebuffer, the background and the
// primitive queries. The path (render_path.h) owns the rest.
struct Renderer::Impl {
  Impl(const meshes::Mesh& mesh, const cpca::CompressedSet* set, const prt::TransferSet* transfer,
       const probes::Probe* probe, const RendererOptions& renderer_options);

  void update(const Camera& camera, const Eigen::Ref<const prt::ShLighting>& lighting,
              const Eigen::Matrix3d& rotation_matrix);
  void draw(const Camera& camera, const Eigen::Matrix3d& rotation_matrix);
  void read_queries();

  RendererOptions options;
  RenderStats stats;
  std::unique_ptr<RenderPath> path;
  BackgroundPass background_pass;
  Background background;
  FrameTarget target;
  std::vector<GLuint> queries;
  WorkCounter work;
  prt::ShRotation rotation{1, Eigen::Matrix3d::Identity()};
  Eigen::MatrixXd lit;

  ~Impl() {
    if (!queries.empty()) glDeleteQueries(GLsizei(queries.size()), queries.data());
  }
};

namespace {

// The mesh check every path needs, and the stats of one pass over the whole mesh (the
// multipass path replaces them with its own).
RenderStats initial_stats(const meshes::Mesh& mesh) {
  if (!mesh.has_frames())
    throw std::invalid_argument(
        "Renderer: the mesh has no tangent frames; run meshes::compute_frames");
  RenderStats stats;
  stats.vertex_count = mesh.vertex_count();
  stats.triangle_count = mesh.triangle_count();
  stats.triangles_per_pass = {mesh.triangle_count()};
  return stats;
}

}  // namespace

// kAuto: half floats on a hardware GPU; Mesa's software rasterisers (llvmpipe, softpipe)
// gain nothing from them.
Accumulation resolve_accumulation(Accumulation wanted) {
  if (wanted != Accumulation::kAuto) return wanted;
  return current_gl_info().software_rasterizer() ? Accumulation::kFloat32 : Accumulation::kFloat16;
}

Renderer::Impl::Impl(const meshes::Mesh& mesh, const cpca::CompressedSet* set,
                     const prt::TransferSet* transfer, const probes::Probe* probe,
                     const RendererOptions& renderer_options)
    : options(renderer_options),
      stats(initial_stats(mesh)),
      path(make_render_path({mesh, set, transfer, options, stats})),
      background_pass(probe) {
  const int order = options.mode == Mode::kUncompressed ? transfer->order : set->order;
  rotation = prt::ShRotation(order, Eigen::Matrix3d::Identity());
  lit.resize(order * order, 3);
  background.use_probe = background_pass.has_probe();
  stats.accumulation = resolve_accumulation(options.accumulation);
  check_gl("Renderer: set-up");
}

void Renderer::Impl::update(const Camera& camera, const Eigen::Ref<const prt::ShLighting>& lighting,
                            const Eigen::Matrix3d& rotation_matrix) {
  if (lighting.rows() != lit.rows())
    throw std::invalid_argument("lighting has " + std::to_string(lighting.rows()) +
                                " SH rows; the data is order " + std::to_string(rotation.order()) +
                                " (" + std::to_string(lit.rows()) +
                                " rows): project the probe at that order");
  rotation.set(rotation_matrix);
  rotation.apply(lighting, lit);
  path->update(lit, camera);
}

void Renderer::Impl::draw(const Camera& camera, const Eigen::Matrix3d& rotation_matrix) {
  target.bind(camera.width, camera.height, stats.accumulation == Accumulation::kFloat16);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glClearDepth(1.0);
  work.reset();
  // A probe background writes every pixel (alpha 0: not coverage) and so replaces the colour
  // clear, which costs llvmpipe at RGBA32F about what the whole pass costs without its tap.
  // Every path then writes each pixel its depth test passes (the multipass pre-pass writes
  // (0, 0, 0, 1), so the additive passes start at zero). Not flushed: in one scene with the
  // mesh, llvmpipe shades each tile's background and mesh together while the tile is in
  // cache, which measured faster than flushing the background to the rasterizer threads
  // ahead of the mesh's vertex work (docs/BENCHMARKS.md "### Background"). A solid
  // background is the clear colour (alpha 0).
  const bool probe_background = background.use_probe && background_pass.has_probe();
  if (probe_background) {
    glClear(GL_DEPTH_BUFFER_BIT);
    if (options.count_work) work.begin("background", 3);
    background_pass.draw(camera, rotation_matrix);
    if (options.count_work) work.end();
    glDepthMask(GL_TRUE);  // the pass turns depth writes off
  } else {
    glClearColor(background.colour.x(), background.colour.y(), background.colour.z(), 0.f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);  // the multipass path leaves GL_EQUAL in a context renderers share
  glDisable(GL_BLEND);
  if (options.cull_back_faces) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
  } else {
    glDisable(GL_CULL_FACE);
  }
  path->mesh().bind();
  if (options.count_primitives && queries.size() < path->passes()) {
    if (!queries.empty()) glDeleteQueries(GLsizei(queries.size()), queries.data());
    queries.assign(path->passes(), 0);
    glGenQueries(GLsizei(queries.size()), queries.data());
  }
  path->set_work_counter(options.count_work ? &work : nullptr);
  path->draw_depth(camera);
  path->draw(camera, options.count_primitives ? queries : std::vector<GLuint>{});
  glDepthMask(GL_TRUE);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  path->mesh().bind();
}

void Renderer::Impl::read_queries() {
  stats.measured_triangles.clear();
  for (std::size_t p = 0; p < path->passes(); ++p) {
    GLuint value = 0;  // libOSMesa exports the 32-bit query getter only
    if (path->pass_drew(p)) glGetQueryObjectuiv(queries[p], GL_QUERY_RESULT, &value);
    stats.measured_triangles.push_back(value);
  }
}

Renderer::Renderer(const meshes::Mesh& mesh, const cpca::CompressedSet* set,
                   const prt::TransferSet* transfer, const probes::Probe* probe,
                   const RendererOptions& options)
    : impl_(std::make_unique<Impl>(mesh, set, transfer, probe, options)) {}

Renderer::~Renderer() = default;

void Renderer::set_background(const Background& background) {
  impl_->background = background;
}

void Renderer::set_probe(const probes::Probe* probe) {
  impl_->background_pass.set_probe(probe);
}

void Renderer::set_count_work(bool on) {
  impl_->options.count_work = on;
}

void Renderer::set_count_primitives(bool on) {
  impl_->options.count_primitives = on;
}

FrameTiming Renderer::render(const Camera& camera,
                             const Eigen::Ref<const prt::ShLighting>& lighting,
                             const Eigen::Matrix3d& rotation) {
  camera.validate();
  FrameTiming timing;
  const auto start = Clock::now();
  impl_->update(camera, lighting, rotation);
  timing.cpu_ms = ms_since(start);
  const auto gl_start = Clock::now();
  impl_->draw(camera, rotation);
  glFinish();
  timing.gl_ms = ms_since(gl_start);
  timing.total_ms = ms_since(start);
  if (impl_->options.count_primitives) impl_->read_queries();
  if (impl_->options.count_work) impl_->stats.pass_work = impl_->work.read();
  check_gl("Renderer::render");
  return timing;
}

Image Renderer::read_image() const {
  Image image;
  read_image(image);
  return image;
}

void Renderer::read_image(Image& into) const {
  impl_->target.read(into);
}

std::vector<Rgb> Renderer::capture_vertex_radiance(
    const Camera& camera, const Eigen::Ref<const prt::ShLighting>& lighting,
    const Eigen::Matrix3d& rotation) {
  impl_->update(camera, lighting, rotation);
  // The capture discards rasterisation, but a draw still needs a complete framebuffer: a
  // surfaceless EGL context has no default one (GL_INVALID_FRAMEBUFFER_OPERATION).
  impl_->target.bind(camera.width, camera.height);
  const GpuMesh& mesh = impl_->path->mesh();
  mesh.bind();
  const std::vector<Rgb> gpu = impl_->path->capture(camera);
  check_gl("Renderer::capture_vertex_radiance");
  // Copies of a vertex (per-pass blocks) capture the same radiance; any one will do.
  std::vector<Rgb> out(mesh.source_vertex_count());
  for (std::size_t i = 0; i < gpu.size(); ++i) out[mesh.old_of_new()[i]] = gpu[i];
  return out;
}

const RenderStats& Renderer::stats() const {
  return impl_->stats;
}

Mode Renderer::mode() const {
  return impl_->options.mode;
}

TimingSummary measure(Renderer& renderer, const Camera& camera,
                      const Eigen::Ref<const prt::ShLighting>& lighting,
                      const Eigen::Matrix3d& start_rotation, const Eigen::Vector3d& axis,
                      double degrees_per_frame, int frames, int warmup, double warmup_ms) {
  if (frames < 1) throw std::invalid_argument("--frames must be >= 1");
  if (warmup_ms < 0) warmup_ms = current_gl_info().software_rasterizer() ? 0.0 : 300.0;
  std::vector<double> total, cpu, gl;
  const auto warmup_start = Clock::now();
  for (int f = -warmup; f < frames; ++f) {
    const Eigen::Matrix3d r = prt::axis_angle(axis.normalized(), degrees_per_frame * (f + warmup) *
                                                                     std::numbers::pi / 180.0) *
                              start_rotation;
    const FrameTiming t = renderer.render(camera, lighting, r);
    if (f == -1 && ms_since(warmup_start) < warmup_ms) --f;  // the warm-up's last frame again
    if (f < 0) continue;
    total.push_back(t.total_ms);
    cpu.push_back(t.cpu_ms);
    gl.push_back(t.gl_ms);
  }
  TimingSummary s;
  s.frames = frames;
  s.frame_ms_median = median(total);
  s.cpu_ms_median = median(cpu);
  s.gl_ms_median = median(gl);
  s.fps = s.frame_ms_median > 0 ? 1000.0 / s.frame_ms_median : 0.0;
  return s;
}

}  // namespace render
