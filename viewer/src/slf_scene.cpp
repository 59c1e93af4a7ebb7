#include "viewer/slf_scene.h"

#include "render/slf_renderer.h"
#include "render/supersample.h"

#include <chrono>
#include <cstdio>

namespace viewer {
// Named rather than anonymous: the unity build compiles scene.cpp's helpers in the same unit.
namespace slf_scene {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace slf_scene

void check_slf_request(const ViewState& s, const std::string& name) {
  const ViewState plain;
  const std::string baked = ": the lighting is baked into " + name + "; orbit the camera instead";
  if (s.env_yaw != 0) throw RequestError("env_yaw=" + slf_scene::number(s.env_yaw) + baked);
  if (s.env_pitch != 0) throw RequestError("env_pitch=" + slf_scene::number(s.env_pitch) + baked);
  if (s.probe != 0)
    throw RequestError("probe=" + std::to_string(s.probe) + ": " + name +
                       " shows only the probe it was baked under (probe=0)");
  if (s.overlay != Overlay::kNone)
    throw RequestError(std::string("overlay=") + kOverlayNames.name(s.overlay) + ": " + name +
                       " is a surface light field, drawn in one pass; use overlay=none");
  const auto one_compression = [&](const char* key, int value) {
    if (value != 0)
      throw RequestError(std::string(key) + "=" + std::to_string(value) + ": " + name +
                         " holds one compression; use " + key + "=0 (its own)");
  };
  one_compression("clusters", s.clusters);
  one_compression("pcs", s.pcs);
  one_compression("order", s.order);
  const std::string one_pass = ": " + name + " is a surface light field, drawn in one pass";
  if (s.mode != plain.mode)
    throw RequestError(std::string("mode=") + render::kModeNames.name(s.mode) + one_pass);
  if (s.strategy != plain.strategy) throw RequestError("strategy=" + s.strategy + one_pass);
  if (s.register_budget != 0)
    throw RequestError("budget=" + std::to_string(s.register_budget) + one_pass);
  if (s.clusters_per_pass != 0)
    throw RequestError("cpp=" + std::to_string(s.clusters_per_pass) + one_pass);
}

struct SlfScene::Impl {
  explicit Impl(SlfSceneInputs in) : inputs(std::move(in)) {}

  void render_into(RenderedFrame& frame);

  SlfSceneInputs inputs;
  render::GlContext context{inputs.gl};
  SceneInfo info;
  std::unique_ptr<render::SlfRenderer> renderer;
  int clusters = 0, components = 0;
};

void SlfScene::Impl::render_into(RenderedFrame& frame) {
  const ViewState& s = frame.state;
  check_slf_request(s, inputs.name);
  const auto start = slf_scene::Clock::now();
  const render::Camera camera = view_camera(inputs.camera, *inputs.mesh, s);
  // Anti-aliased frames: the same view at `samples` times the size, box-filtered, as the PRT
  // scene's.
  const render::Camera drawn = s.samples > 1 ? render::supersampled(camera, s.samples) : camera;
  const render::FrameTiming t = renderer->render(drawn);
  const auto read_start = slf_scene::Clock::now();
  renderer->read_image(frame.image);
  if (s.samples > 1) frame.image = render::box_downsample(frame.image, s.samples);
  frame.stats.readback_ms = slf_scene::ms_since(read_start);
  frame.stats.render_ms = slf_scene::ms_since(start);
  frame.stats.frame_ms = t.total_ms;
  frame.stats.cpu_ms = t.cpu_ms;
  frame.stats.gl_ms = t.gl_ms;
  frame.stats.kind = "slf";
  frame.stats.passes = 1;
  frame.stats.clusters_per_pass = clusters;
  frame.stats.clusters = clusters;
  frame.stats.pcs = components;
}

SlfScene::SlfScene(SlfSceneInputs inputs) : impl_(std::make_unique<Impl>(std::move(inputs))) {
  Impl& m = *impl_;
  m.info = context_scene_info(m.context.info());
  render::SlfRendererOptions ro;
  ro.cull_back_faces = m.inputs.cull_back_faces;
  ro.shading = m.inputs.shading;
  m.renderer = std::make_unique<render::SlfRenderer>(*m.inputs.model, m.inputs.probe, ro);
  m.renderer->set_background(m.inputs.background);
  m.clusters = m.inputs.model->clusters;
  m.components = m.inputs.model->components;
  m.inputs.model = nullptr;  // uploaded; the caller may free it
}

SlfScene::~SlfScene() = default;

const SceneInfo& SlfScene::info() const {
  return impl_->info;
}

std::shared_ptr<RenderedFrame> SlfScene::render(const ViewState& state) {
  auto frame = std::make_shared<RenderedFrame>();
  frame->state = state;
  try {
    impl_->render_into(*frame);
  } catch (const std::invalid_argument& e) {  // RequestError, or a camera the state breaks
    frame->request_error = e.what();
  } catch (const std::exception& e) {
    frame->server_error = e.what();
  }
  if (!frame->request_error.empty() || !frame->server_error.empty()) frame->image = {};
  return frame;
}

}  // namespace viewer
