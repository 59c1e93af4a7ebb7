#include "background_pass.h"

#include "render/gl_context.h"
#include "render/glm_eigen.h"
#include "render/shader_source.h"

#include <glm/gtc/type_ptr.hpp>

#include <cmath>
#include <numbers>
#include <vector>

namespace render {

BackgroundPass::BackgroundPass(const probes::Probe* probe)
    : program_("background", background_vertex_shader(), background_fragment_shader()) {
  glGenVertexArrays(1, &vao_);
  glGenTextures(1, &texture_);
  set_probe(probe);
}

void BackgroundPass::set_probe(const probes::Probe* probe) {
  glBindTexture(GL_TEXTURE_2D, texture_);
  std::vector<float> texels;
  int tw = 2, th = 1;
  have_probe_ = false;
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
  const glm::dvec3 f = glm::normalize(to_glm(camera.target) - to_glm(camera.eye));
  const glm::dvec3 r = glm::normalize(glm::cross(f, to_glm(camera.up)));
  const glm::dvec3 u = glm::cross(r, f);
  const double t = std::tan(0.5 * glm::radians(camera.fov_y_degrees));
  const glm::vec3 ff(f), rr(r * t * camera.aspect()), uu(u * t);
  glUniform3fv(program_.uniform("u_forward"), 1, glm::value_ptr(ff));
  glUniform3fv(program_.uniform("u_right"), 1, glm::value_ptr(rr));
  glUniform3fv(program_.uniform("u_up"), 1, glm::value_ptr(uu));
  // Radiance toward w is probe(R^T w).
  const glm::mat3 probe_from_world(glm::transpose(glm::dmat3(to_glm(rotation))));
  glUniformMatrix3fv(program_.uniform("u_probe_from_world"), 1, GL_FALSE,
                     glm::value_ptr(probe_from_world));
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glUniform1i(program_.uniform("u_probe"), 0);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace render
