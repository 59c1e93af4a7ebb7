// render/src/background_pass.h (private): the environment behind the mesh, the probe rotated
// by R (radiance toward w is probe(R^T w)), drawn as one full-screen triangle at depth 1 after
// the mesh so only uncovered pixels pay for it (docs/ARCHITECTURE.md "Rendering").
#pragma once

#include "gl_program.h"
#include "probes/probe.h"
#include "render/camera.h"

#include <Eigen/Core>

namespace render {

class BackgroundPass {
 public:
  // `probe` may be null or empty (then has_probe() is false and draw is never needed); its
  // texels are uploaded here and not kept.
  explicit BackgroundPass(const probes::Probe* probe);
  ~BackgroundPass();
  BackgroundPass(const BackgroundPass&) = delete;
  BackgroundPass& operator=(const BackgroundPass&) = delete;

  // Replaces the texture (a viewer switching probes); same rules as the constructor.
  void set_probe(const probes::Probe* probe);
  bool has_probe() const { return have_probe_; }
  // Where the depth buffer still holds the cleared 1.0; colour only, alpha kept (coverage).
  void draw(const Camera& camera, const Eigen::Matrix3d& rotation);

 private:
  GLuint texture_ = 0, vao_ = 0;
  GlProgram program_;
  bool have_probe_ = false;
};

}  // namespace render
