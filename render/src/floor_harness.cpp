#include "render/floor_harness.h"

#include "background_pass.h"
#include "frame_target.h"
#include "gl_program.h"
#include "median.h"
#include "render/gl_context.h"
#include "render/shader_source.h"
#include "work_counter.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <vector>

namespace render {

namespace {

// The draw's index buffer, and its positions: in cache order with first-use vertex numbering
// when asked, as every render path's draws have (gpu_mesh.h).
std::vector<std::uint32_t> floor_indices(const meshes::Mesh& mesh, const FloorOptions& options,
                                         std::vector<meshes::Vec3>* positions) {
  std::vector<std::uint32_t> indices;
  indices.reserve(mesh.triangle_count() * 3);
  for (const auto& t : mesh.triangles) indices.insert(indices.end(), t.begin(), t.end());
  *positions = mesh.positions;
  if (!options.optimize_vertex_cache) return indices;
  std::vector<std::uint32_t> optimised(indices.size());
  meshopt_optimizeVertexCache(optimised.data(), indices.data(), indices.size(),
                              mesh.vertex_count());
  meshopt_optimizeVertexFetch(positions->data(), optimised.data(), optimised.size(),
                              mesh.positions.data(), mesh.vertex_count(), sizeof(meshes::Vec3));
  return optimised;
}

}  // namespace

double floor_frame_ms(const meshes::Mesh& mesh, const Camera& camera, const FloorOptions& options) {
  camera.validate();
  std::vector<meshes::Vec3> positions;
  const std::vector<std::uint32_t> indices = floor_indices(mesh, options, &positions);
  GLuint vao = 0, vbo = 0, ibo = 0;
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.vertex_count() * 12), positions.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(kAttrPosition);
  glVertexAttribPointer(kAttrPosition, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glGenBuffers(1, &ibo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * 4), indices.data(),
               GL_STATIC_DRAW);
  FrameTarget target;  // the renderer's framebuffer, so the floor measures the same target
  target.bind(camera.width, camera.height);
  GlProgram program("floor", position_vertex_shader(), constant_fragment_shader());
  program.use();
  const Eigen::Matrix4f clip = camera.clip_from_world().cast<float>();
  glUniformMatrix4fv(program.uniform("u_clip_from_world"), 1, GL_FALSE, clip.data());
  glUniform3f(program.uniform("u_colour"), 0.5f, 0.5f, 0.5f);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  if (options.cull_back_faces) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
  } else {
    glDisable(GL_CULL_FACE);
  }
  std::optional<BackgroundPass> background;
  if (options.background) background.emplace(options.background);
  std::vector<std::uint32_t> sorted = indices;
  std::sort(sorted.begin(), sorted.end());
  const auto referenced = std::uint64_t(std::unique(sorted.begin(), sorted.end()) - sorted.begin());
  WorkCounter counter;
  std::vector<double> ms;
  for (int f = -options.warmup; f < options.frames; ++f) {
    const bool count = options.work && f + 1 == options.frames;
    const auto start = std::chrono::steady_clock::now();
    // Masks before the clear: the background pass leaves depth writes off, and glClear
    // honours the masks (the mesh would then fail GL_LESS against last frame's depth).
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(0.f, 0.f, 0.f, 0.f);
    // As the renderer draws it: the background first, in place of the colour clear.
    if (background) {
      glClear(GL_DEPTH_BUFFER_BIT);
      if (count) counter.begin("background", 3);
      background->draw(camera, Eigen::Matrix3d::Identity());
      if (count) counter.end();
      glEnable(GL_DEPTH_TEST);
      glDepthMask(GL_TRUE);
    } else {
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }
    program.use();
    glBindVertexArray(vao);
    glDepthFunc(GL_LESS);
    if (options.cull_back_faces) glEnable(GL_CULL_FACE);
    if (count) counter.begin("mesh", referenced);
    glDrawElements(GL_TRIANGLES, GLsizei(indices.size()), GL_UNSIGNED_INT, nullptr);
    if (count) counter.end();
    glFinish();
    if (count) *options.work = counter.read();
    if (options.last_frame && f + 1 == options.frames) *options.last_frame = target.read();
    if (f >= 0)
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
  }
  check_gl("floor_frame_ms");
  glDisable(GL_CULL_FACE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteBuffers(1, &vbo);
  glDeleteBuffers(1, &ibo);
  glDeleteVertexArrays(1, &vao);
  return median(std::move(ms));
}

}  // namespace render
