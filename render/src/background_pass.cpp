#include "background_pass.h"

#include "probes/cube_map.h"
#include "render/gl_context.h"
#include "render/glm_eigen.h"
#include "render/shader_source.h"

#include <tbb/parallel_for.h>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
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

namespace {

// The cubic B-spline of the probe's texels at the lat-long point of d (wrapping in u,
// clamping in v, texel centres at half-integers): the look the background keeps.
Eigen::Vector3f bspline(const probes::Probe& probe, const Eigen::Vector3d& d) {
  const double theta = std::acos(std::clamp(d.y(), -1.0, 1.0));
  double phi = std::atan2(-d.x(), d.z());
  if (phi < 0) phi += 2 * std::numbers::pi;
  const double px = phi / (2 * std::numbers::pi) * probe.width() - 0.5;
  const double py = theta / std::numbers::pi * probe.height() - 0.5;
  const double ix = std::floor(px), iy = std::floor(py);
  auto weights = [](double f) {
    const double w0 = (1 - f) * (1 - f) * (1 - f) / 6, w3 = f * f * f / 6;
    const double w1 = (3 * f * f * f - 6 * f * f + 4) / 6;
    return std::array<double, 4>{w0, w1, 1 - w0 - w1 - w3, w3};
  };
  const auto wx = weights(px - ix), wy = weights(py - iy);
  const int w = probe.width(), h = probe.height();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int j = 0; j < 4; ++j) {
    const int y = std::clamp(int(iy) - 1 + j, 0, h - 1);
    for (int i = 0; i < 4; ++i) {
      const int x = ((int(ix) - 1 + i) % w + w) % w;
      sum += wx[std::size_t(i)] * wy[std::size_t(j)] * probe.texel(x, y).cast<double>();
    }
  }
  return sum.cast<float>();
}

// Face size: 3 cube texels per lat-long texel at a face's centre (2 / size radians against
// 2 pi / width), so that one bilinear tap between the B-spline's samples stays within 2 %
// of the B-spline itself at the 99th percentile where a probe is most magnified
// (tests/render_renderer_test.cpp, RealProbeBackgroundFollowsTheBspline: 1.5 texels gave
// 7 %); at least 128, so small probes are sampled finely, and at most 2048.
int cube_face_size(const probes::Probe& probe) {
  const int size = int(std::ceil(3.0 * probe.width() / std::numbers::pi));
  return std::clamp((size + 3) / 4 * 4, 128, 2048);
}

}  // namespace

void BackgroundPass::set_probe(const probes::Probe* probe) {
  have_probe_ = probe && probe->width() > 0;
  if (!have_probe_) return;
  // Resampled once per probe: per pixel, only the rotation changes, and one hardware cube
  // tap costs a fraction of the lat-long B-spline's two arctangents and four bilinear taps.
  const int size = cube_face_size(*probe);
  std::vector<float> texels(std::size_t(size) * std::size_t(size) * 4);
  glBindTexture(GL_TEXTURE_CUBE_MAP, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int face = 0; face < 6; ++face) {
    tbb::parallel_for(0, size, [&](int t) {
      for (int s = 0; s < size; ++s) {
        const double sc = 2.0 * (s + 0.5) / size - 1.0, tc = 2.0 * (t + 0.5) / size - 1.0;
        const Eigen::Vector3f c =
            bspline(*probe, probes::CubeMap::face_direction(face, sc, tc).normalized());
        float* out = &texels[(std::size_t(t) * std::size_t(size) + std::size_t(s)) * 4];
        // Half floats end at 65504: clamp rather than store infinity.
        for (int k = 0; k < 3; ++k) out[k] = std::clamp(c[k], -65504.f, 65504.f);
        out[3] = 1.f;
      }
    });
    glTexImage2D(GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face), 0, GL_RGBA16F, size, size, 0,
                 GL_RGBA, GL_FLOAT, texels.data());
  }
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
    glTexParameteri(GL_TEXTURE_CUBE_MAP, wrap, GL_CLAMP_TO_EDGE);
  check_gl("Renderer: background");
}

BackgroundPass::~BackgroundPass() {
  glDeleteVertexArrays(1, &vao_);
  glDeleteTextures(1, &texture_);
}

void BackgroundPass::draw(const Camera& camera, const Eigen::Matrix3d& rotation) {
  glBindVertexArray(vao_);
  program_.use();
  // Opaque over the whole target: llvmpipe then shades whole tiles without depth reads,
  // masks or read-modify-writes, and the pass replaces the RGBA32F colour clear. Measured
  // against the depth-tested pass after the mesh (only uncovered pixels, alpha masked),
  // this is cheaper on the bunny frame although it shades the covered pixels too
  // (docs/BENCHMARKS.md "### Background").
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glDisable(GL_BLEND);
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
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);  // filter across face edges: no seams
  glBindTexture(GL_TEXTURE_CUBE_MAP, texture_);
  glUniform1i(program_.uniform("u_probe"), 0);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace render
