#include "viewer/scene.h"

#include "cpca/supercluster_strategy.h"
#include "difference.h"
#include "probes/load.h"
#include "prt/projection.h"
#include "prt/sh_rotation.h"
#include "prt/transfer_file.h"
#include "render/gl_context.h"
#include "render/pass_grouping.h"
#include "render/renderer.h"
#include "render/shading.h"
#include "render/supersample.h"
#include "viewer/encode.h"

#include <chrono>
#include <cstdlib>
#include <list>
#include <map>
#include <numbers>
#include <optional>
#include <thread>

namespace viewer {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}
double radians(double degrees) {
  return degrees * std::numbers::pi / 180.0;
}

// Renderers are large (per-pass vertex blocks, constants) and slow to build (grouping,
// uploads), so a few are kept for switching back and forth, not one per combination.
constexpr std::size_t kRenderersKept = 3;
constexpr std::size_t kProbesKept = 2;        // texels for uploads; SH lighting is kept for all
constexpr double kDifferenceFullScale = 0.1;  // the difference view's red: 10 % or more

std::string renderer_key(const ViewState& s, const cpca::CompressedSet& set) {
  const bool grouped = s.mode == render::Mode::kMultipass || s.mode == render::Mode::kDecoupled;
  return std::string(render::kModeNames.name(s.mode)) + "/" + (grouped ? s.strategy : "-") + "/" +
         std::to_string(s.register_budget) + "/" + std::to_string(s.clusters_per_pass) + "/" +
         std::to_string(set.cluster_count) + "x" + std::to_string(set.component_count) + "/o" +
         std::to_string(set.order);
}

}  // namespace

// Outside the anonymous namespace: Impl holds a list of them, and a class with a member of
// internal-linkage type is an error-prone mix (GCC warns once the file is in a unity unit).
struct CachedRenderer {
  std::string key;
  std::shared_ptr<const cpca::CompressedSet> set;  // kept alive while its renderer is
  std::unique_ptr<render::Renderer> renderer;
  std::vector<std::uint8_t> pass_counts;             // per triangle, for the overdraw overlay
  int probe = -1;                                    // the probe its background texture holds
  std::shared_ptr<const prt::TransferSet> transfer;  // the uncompressed mode's, kept alive
};

struct ViewScene::Impl {
  explicit Impl(SceneInputs in) : inputs(std::move(in)) {}

  CachedRenderer& renderer_for(const ViewState& state, const CompressionStatus& compression);
  const prt::ShLighting& lighting_for(int probe, int order);
  std::shared_ptr<const prt::TransferSet> transfer_for(const std::filesystem::path& path);
  const probes::Probe& probe_texels(int probe);
  std::vector<std::uint8_t> pass_counts(const render::Renderer& r, const cpca::CompressedSet& set,
                                        const std::optional<cpca::SuperClusters>& groups) const;
  void add_overlay(RenderedFrame& frame, const CachedRenderer& cached,
                   const render::Camera& camera) const;
  void add_difference(RenderedFrame& frame, const render::Camera& drawn, const prt::ShLighting& sh,
                      const CompressionStatus& compression);
  void render_into(RenderedFrame& frame);

  SceneInputs inputs;
  render::GlContext context{inputs.gl};
  SceneInfo info;
  std::list<CachedRenderer> renderers;                      // most recently used first
  std::map<std::pair<int, int>, prt::ShLighting> lighting;  // by probe and SH order
  std::list<std::pair<int, probes::Probe>> probes_loaded;   // most recently used first
  // The last bake loaded (a renderer keeps its own alive): one at a time, as they are large.
  std::filesystem::path transfer_path;
  std::weak_ptr<const prt::TransferSet> transfer;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
};

const probes::Probe& ViewScene::Impl::probe_texels(int probe) {
  for (auto it = probes_loaded.begin(); it != probes_loaded.end(); ++it)
    if (it->first == probe) {
      probes_loaded.splice(probes_loaded.begin(), probes_loaded, it);
      return probes_loaded.front().second;
    }
  probes_loaded.emplace_front(probe, probes::load_probe(inputs.probes.at(std::size_t(probe))));
  if (probes_loaded.size() > kProbesKept) probes_loaded.pop_back();
  return probes_loaded.front().second;
}

const prt::ShLighting& ViewScene::Impl::lighting_for(int probe, int order) {
  auto it = lighting.find({probe, order});
  if (it == lighting.end())
    it = lighting.emplace(std::pair{probe, order}, prt::project(probe_texels(probe), order)).first;
  return it->second;
}

std::shared_ptr<const prt::TransferSet> ViewScene::Impl::transfer_for(
    const std::filesystem::path& path) {
  if (auto loaded = transfer.lock(); loaded && path == transfer_path) return loaded;
  auto loaded = std::make_shared<const prt::TransferSet>(prt::read_transfer(path));
  transfer = loaded;
  transfer_path = path;
  return loaded;
}

std::vector<std::uint8_t> ViewScene::Impl::pass_counts(
    const render::Renderer& r, const cpca::CompressedSet& set,
    const std::optional<cpca::SuperClusters>& groups) const {
  const meshes::Mesh& mesh = *inputs.mesh;
  if (r.mode() != render::Mode::kMultipass)
    return std::vector<std::uint8_t>(mesh.triangle_count(), 1);
  const std::vector<cpca::TriangleIndices> triangles(mesh.triangles.begin(), mesh.triangles.end());
  if (groups) return cpca::triangle_pass_counts(set.cluster_of, triangles, *groups);
  // No grouping given: the renderer filled its passes in cluster order.
  const cpca::SuperClusterInput input{set.cluster_of, triangles, set.cluster_count,
                                      r.stats().clusters_per_pass};
  return cpca::triangle_pass_counts(set.cluster_of, triangles,
                                    cpca::group_clusters("order", input));
}

CachedRenderer& ViewScene::Impl::renderer_for(const ViewState& state,
                                              const CompressionStatus& compression) {
  const std::shared_ptr<const cpca::CompressedSet>& set = compression.shown;
  const std::string key = renderer_key(state, *set);
  for (auto it = renderers.begin(); it != renderers.end(); ++it)
    if (it->key == key) {
      renderers.splice(renderers.begin(), renderers, it);
      return renderers.front();
    }
  // Free the least recently used one first: two bunny renderers at once cost memory.
  if (renderers.size() >= kRenderersKept) renderers.pop_back();
  render::RendererOptions ro;
  ro.mode = state.mode;
  ro.register_budget = state.register_budget;
  ro.clusters_per_pass = state.clusters_per_pass;
  std::optional<cpca::SuperClusters> groups;
  if (ro.mode == render::Mode::kMultipass || ro.mode == render::Mode::kDecoupled)
    ro.groups = groups = render::group_for_renderer(*inputs.mesh, *set, context, ro.register_budget,
                                                    ro.clusters_per_pass, state.strategy);
  CachedRenderer cached;
  if (ro.mode == render::Mode::kUncompressed) cached.transfer = transfer_for(compression.transfer);
  const probes::Probe& probe = probe_texels(state.probe);
  cached.key = key;
  cached.set = set;
  cached.renderer = std::make_unique<render::Renderer>(*inputs.mesh, set.get(),
                                                       cached.transfer.get(), &probe, ro);
  cached.renderer->set_background(inputs.background);
  cached.pass_counts = pass_counts(*cached.renderer, *set, groups);
  cached.probe = state.probe;
  renderers.push_front(std::move(cached));
  return renderers.front();
}

void ViewScene::Impl::add_overlay(RenderedFrame& frame, const CachedRenderer& cached,
                                  const render::Camera& camera) const {
  if (frame.state.overlay == Overlay::kNone) return;
  const auto start = Clock::now();
  render::PictureOptions po;
  po.background = kOverlayTransparent;
  if (frame.state.overlay == Overlay::kOverdraw)
    frame.overlay = render::overdraw_picture(*inputs.mesh, camera, cached.pass_counts, po);
  else
    frame.overlay = render::cluster_picture(*inputs.mesh, camera, cached.set->cluster_of, po);
  frame.stats.overlay_ms = ms_since(start);
}

void ViewScene::Impl::render_into(RenderedFrame& frame) {
  const ViewState& s = frame.state;
  const auto start = Clock::now();
  const auto setup_start = Clock::now();
  const CompressionStatus compression = inputs.compressions->choose(s.clusters, s.pcs, s.order);
  frame.stats.clusters = compression.shown->cluster_count;
  frame.stats.pcs = compression.shown->component_count;
  frame.stats.order = compression.shown->order;
  frame.stats.compressing = compression.pending;
  frame.stats.compress_progress = compression.progress;
  frame.stats.compress_error = compression.error;
  CachedRenderer& cached = renderer_for(s, compression);
  const prt::ShLighting& sh = lighting_for(s.probe, compression.shown->order);
  if (cached.probe != s.probe) {
    cached.renderer->set_probe(&probe_texels(s.probe));
    cached.probe = s.probe;
  }
  frame.stats.setup_ms = ms_since(setup_start);
  const render::Camera camera = view_camera(inputs.camera, *inputs.mesh, s);
  // Anti-aliased frames render the same view at `samples` times the size and box-filter it
  // (render/supersample.h, as relight's frames); the overlays are drawn at the output size.
  const render::Camera drawn = s.samples > 1 ? render::supersampled(camera, s.samples) : camera;
  const render::FrameTiming t = cached.renderer->render(drawn, sh, environment_rotation(axis, s));
  const auto read_start = Clock::now();
  cached.renderer->read_image(frame.image);
  if (s.samples > 1) frame.image = render::box_downsample(frame.image, s.samples);
  frame.stats.readback_ms = ms_since(read_start);
  frame.stats.render_ms = ms_since(start);
  frame.stats.frame_ms = t.total_ms;
  frame.stats.cpu_ms = t.cpu_ms;
  frame.stats.gl_ms = t.gl_ms;
  const render::RenderStats& rs = cached.renderer->stats();
  frame.stats.passes = rs.passes;
  frame.stats.average_overdraw = rs.average_overdraw;
  frame.stats.clusters_per_pass = rs.clusters_per_pass;
  frame.stats.register_budget = rs.register_budget;
  if (s.overlay == Overlay::kDifference)
    add_difference(frame, drawn, sh, compression);
  else
    add_overlay(frame, cached, camera);
}

// The same view through the uncompressed transfer (its own cached renderer), then the
// difference picture of the two.
void ViewScene::Impl::add_difference(RenderedFrame& frame, const render::Camera& drawn,
                                     const prt::ShLighting& sh,
                                     const CompressionStatus& compression) {
  const auto start = Clock::now();
  const ViewState& s = frame.state;
  ViewState reference_state = s;
  reference_state.mode = render::Mode::kUncompressed;
  CachedRenderer& reference = renderer_for(reference_state, compression);
  if (reference.probe != s.probe) {
    reference.renderer->set_probe(&probe_texels(s.probe));
    reference.probe = s.probe;
  }
  reference.renderer->render(drawn, sh, environment_rotation(axis, s));
  render::Image exact;
  reference.renderer->read_image(exact);
  if (s.samples > 1) exact = render::box_downsample(exact, s.samples);
  detail::DifferenceStats d;
  frame.overlay =
      detail::difference_picture(frame.image, exact, kDifferenceFullScale, kOverlayTransparent, &d);
  frame.overlay_opacity = 1.0;
  frame.stats.difference_rms = d.rms;
  frame.stats.difference_max = d.max;
  frame.stats.overlay_ms = ms_since(start);
}

ViewScene::ViewScene(SceneInputs inputs) : impl_(std::make_unique<Impl>(std::move(inputs))) {
  Impl& m = *impl_;
  m.axis = m.inputs.axis;
  const render::GlInfo gl = m.context.info();
  m.info = context_scene_info(gl);
  m.info.default_register_budget = gl.default_register_budget();
  m.info.registers_per_cluster =
      render::constant_layout(m.inputs.compressions->launch()).registers_per_cluster();
}

SceneInfo context_scene_info(const render::GlInfo& gl) {
  SceneInfo info;
  info.gl_renderer = gl.renderer;
  info.gl_version = gl.version;
  // llvmpipe's rasteriser threads: LP_NUM_THREADS when set, else one per CPU.
  const char* lp = std::getenv("LP_NUM_THREADS");
  info.llvmpipe_threads = lp ? std::atoi(lp) : int(std::thread::hardware_concurrency());
  info.llvmpipe_threads_source = lp ? "LP_NUM_THREADS" : "CPUs";
  return info;
}

ViewScene::~ViewScene() = default;

const SceneInfo& ViewScene::info() const {
  return impl_->info;
}

std::shared_ptr<RenderedFrame> ViewScene::render(const ViewState& state) {
  auto frame = std::make_shared<RenderedFrame>();
  frame->state = state;
  try {
    impl_->render_into(*frame);
  } catch (const std::invalid_argument& e) {  // a budget too small for one cluster, ...
    frame->request_error = e.what();
  } catch (const std::exception& e) {
    frame->server_error = e.what();
  }
  if (!frame->request_error.empty() || !frame->server_error.empty()) frame->image = {};
  return frame;
}

render::Camera view_camera(const render::CameraPlacement& placement, const meshes::Mesh& mesh,
                           const ViewState& state) {
  const Eigen::Vector3d centre = meshes::bounds(mesh).center().cast<double>();
  double radius = 0.0;
  for (const auto& p : mesh.positions)
    radius = std::max(radius, (p.cast<double>() - centre).norm());
  render::Camera c = render::place_camera(placement, centre, radius, state.width, state.height);
  const Eigen::Vector3d forward = (c.target - c.eye).normalized();
  const Eigen::Vector3d right = forward.cross(c.up).normalized();
  const Eigen::Matrix3d orbit = prt::axis_angle(Eigen::Vector3d::UnitY(), radians(state.cam_yaw)) *
                                prt::axis_angle(right, radians(state.cam_pitch));
  c = render::rotated(c, orbit, c.target);
  c.eye = c.target + (c.eye - c.target) / state.zoom;
  render::fit_clip_planes(c, centre, radius);
  return c;
}

Eigen::Matrix3d environment_rotation(const Eigen::Vector3d& axis, const ViewState& state) {
  return prt::axis_angle(Eigen::Vector3d::UnitX(), radians(state.env_pitch)) *
         prt::axis_angle(axis, radians(state.env_yaw));
}

}  // namespace viewer
