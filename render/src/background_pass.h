// render/src/background_pass.h (private): the environment behind the mesh, the probe rotated
// by R (radiance toward w is probe(R^T w)), drawn as one opaque full-screen triangle before the
// mesh in place of the colour clear (docs/ARCHITECTURE.md "Rendering").
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
  // Every pixel's colour, alpha 0 (not coverage), with the depth test off and depth writes
  // off: draw it first, instead of clearing colour, and let the mesh cover it. Leaves the
  // depth test disabled and culling off; the caller sets its own state after.
  void draw(const Camera& camera, const Eigen::Matrix3d& rotation);

 private:
  GLuint texture_ = 0, vao_ = 0;
  GlProgram program_;
  bool have_probe_ = false;
};

}  // namespace render
