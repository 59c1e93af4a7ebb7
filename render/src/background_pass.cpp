#include "background_pass.h"

#include "render/gl_context.h"
#include "render/shader_source.h"

#include <cmath>
#include <numbers>
#include <vector>

namespace render {

BackgroundPass::BackgroundPass(const probes::Probe* probe)
    : program_("background", background_vertex_shader(), background_fragment_shader()) {
  glGenVertexArrays(1, &vao_);
  glGenTextures(1, &texture_);
  glBindTexture(GL_TEXTURE_2D, texture_);
  std::vector<float> texels;
  int tw = 2, th = 1;
  if (probe && probe->width() > 0) {
    tw = probe->width();
    th = probe->height();
    texels.assign(std::size_t(tw) * th * 4, 1.f);
    for (std::size_t i = 0; i < probe->texels().size(); ++i)
      for (int c = 0; c < 3; ++c) texels[i * 4 + c] = probe->texels()[i][c];
    have_probe_ = true;
  } else {
    texels.assign(8, 0.f);
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, tw, th, 0, GL_RGBA, GL_FLOAT, texels.data());
  // Bilinear between texel centres, wrapping in u and clamping in v: Probe::lookup exactly.
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  check_gl("Renderer: background");
}

BackgroundPass::~BackgroundPass() {
  glDeleteVertexArrays(1, &vao_);
  glDeleteTextures(1, &texture_);
}

void BackgroundPass::draw(const Camera& camera, const Eigen::Matrix3d& rotation) {
  glBindVertexArray(vao_);
  program_.use();
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_FALSE);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  // The world ray is affine in screen position, so the corners' rays interpolate exactly.
  const Eigen::Vector3d f = (camera.target - camera.eye).normalized();
  const Eigen::Vector3d r = f.cross(camera.up).normalized();
  const Eigen::Vector3d u = r.cross(f);
  const double t = std::tan(0.5 * camera.fov_y_degrees * std::numbers::pi / 180.0);
  const Eigen::Vector3f ff = f.cast<float>(), rr = (r * t * camera.aspect()).cast<float>(),
                        uu = (u * t).cast<float>();
  glUniform3fv(program_.uniform("u_forward"), 1, ff.data());
  glUniform3fv(program_.uniform("u_right"), 1, rr.data());
  glUniform3fv(program_.uniform("u_up"), 1, uu.data());
  const Eigen::Matrix3f probe_from_world = rotation.transpose().cast<float>();
  glUniformMatrix3fv(program_.uniform("u_probe_from_world"), 1, GL_FALSE, probe_from_world.data());
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glUniform1i(program_.uniform("u_probe"), 0);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace render
