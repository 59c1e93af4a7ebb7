// viewer/scene.h: the GL side of `prtr view`, owned by its single render thread: the
// OSMesa context, a few renderers (one per mode / strategy / budget, least recently used
// dropped), the probes (projected to SH on first use and cached) and the camera. Turns a
// ViewState into a RenderedFrame. Construct, use and destroy it on one thread.
#pragma once

#include "cpca/compressed.h"
#include "meshes/mesh.h"
#include "render/camera.h"
#include "render/gl_context.h"
#include "render/renderer.h"
#include "viewer/compressions.h"
#include "viewer/frame.h"
#include "viewer/frame_source.h"
#include "viewer/request.h"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace viewer {

struct SceneInputs {
  const meshes::Mesh* mesh = nullptr;
  // The launch's compression and any the page asks for, each with its bake (loaded on the
  // first uncompressed or difference frame at its order).
  Compressions* compressions = nullptr;
  std::vector<std::filesystem::path> probes;
  render::CameraPlacement camera;  // framing before the page orbits it (size comes per request)
  render::Background background;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();  // environment rotation axis (unit)
  render::GlSelection gl;                           // the backend the scene's context is made on
};

// What does not change while the server runs (the page's "about" statistics).
struct SceneInfo {
  std::string gl_renderer, gl_version;
  int llvmpipe_threads = 0;
  std::string llvmpipe_threads_source;  // "LP_NUM_THREADS" or "CPUs"
  int default_register_budget = 0, registers_per_cluster = 0;
};

// The GL context's half of SceneInfo (renderer, version, llvmpipe threads); both scenes show it.
SceneInfo context_scene_info(const render::GlInfo& gl);

class ViewScene : public FrameSource {
 public:
  explicit ViewScene(SceneInputs inputs);
  ~ViewScene() override;
  ViewScene(const ViewScene&) = delete;
  ViewScene& operator=(const ViewScene&) = delete;

  const SceneInfo& info() const;
  std::shared_ptr<RenderedFrame> render(const ViewState& state) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The camera a state asks for: `placement` at the state's size, orbited by cam_yaw about +Y and
// cam_pitch about the camera's right axis around the target, moved zoom times closer; clip planes
// refitted to the mesh.
render::Camera view_camera(const render::CameraPlacement& placement, const meshes::Mesh& mesh,
                           const ViewState& state);

// The environment rotation: env_yaw about `axis`, then env_pitch about +X.
Eigen::Matrix3d environment_rotation(const Eigen::Vector3d& axis, const ViewState& state);

}  // namespace viewer
