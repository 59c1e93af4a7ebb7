// viewer/slf_scene.h: the GL side of `prtr view X.slfc`: a compressed surface light field
// (SLF paper: Miandji, Kronander & Unger, "Geometry Independent Surface Light Fields for Real
// Time Rendering of Precomputed Global Illumination") drawn by render::SlfRenderer in one
// pass. Its lighting was baked under one probe, so of a ViewState only the camera (cam_yaw,
// cam_pitch, zoom), the size, the exposure and the samples per pixel can change; the rest
// must keep the values that mean "as baked", and a state that asks for more is refused with
// the reason (check_slf_request). Construct, use and destroy it on one thread.
#pragma once

#include "meshes/mesh.h"
#include "probes/probe.h"
#include "render/camera.h"
#include "render/gl_context.h"
#include "render/renderer.h"
#include "render/slf_model.h"
#include "render/slf_renderer.h"
#include "viewer/frame_source.h"
#include "viewer/scene.h"

#include <memory>
#include <string>

namespace viewer {

struct SlfSceneInputs {
  const meshes::Mesh* mesh = nullptr;       // frames the camera as the PRT scene's does
  const render::SlfModel* model = nullptr;  // uploaded at construction, not kept
  const probes::Probe* probe = nullptr;     // the probe it was baked under: the background
  std::string name;                         // the .slfc's file name, for refusals
  render::CameraPlacement camera;           // before the page orbits it
  render::Background background;
  render::GlSelection gl;
  bool cull_back_faces = true;
  render::SlfShading shading = render::SlfShading::kAutomatic;
};

class SlfScene : public FrameSource {
 public:
  // Makes the GL context and uploads the model; GlError when the context or a texture fails.
  explicit SlfScene(SlfSceneInputs inputs);
  ~SlfScene() override;
  SlfScene(const SlfScene&) = delete;
  SlfScene& operator=(const SlfScene&) = delete;

  const SceneInfo& info() const;
  // The state's camera, drawn in one pass (stats: passes 1, the model's clusters and k as
  // clusters and pcs); a state check_slf_request refuses is a request_error.
  std::shared_ptr<RenderedFrame> render(const ViewState& state) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// RequestError (one line, naming the parameter first as the page expects) when `state` asks
// the light field `name` for what it cannot show: a turned environment (env_yaw, env_pitch),
// another probe, an overlay, another compression (clusters, pcs, order), or a PRT rendering
// path's setting (mode, strategy, budget, cpp) other than the defaults.
void check_slf_request(const ViewState& state, const std::string& name);

}  // namespace viewer
