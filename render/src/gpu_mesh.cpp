#include "gpu_mesh.h"

#include "common/check.h"
#include "render/gl_context.h"
#include "render/glm_eigen.h"
#include "render/shader_source.h"

#include <meshoptimizer.h>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace render {

GLuint make_buffer(GLenum target, GLsizeiptr bytes, const void* data, GLenum usage) {
  GLuint b = 0;
  glGenBuffers(1, &b);
  glBindBuffer(target, b);
  glBufferData(target, std::max<GLsizeiptr>(bytes, 16), data, usage);
  return b;
}

void set_camera_uniforms(GlProgram& program, const Camera& camera) {
  program.use();
  const glm::mat4 clip(to_glm(camera.clip_from_world()));
  glUniformMatrix4fv(program.uniform("u_clip_from_world"), 1, GL_FALSE, glm::value_ptr(clip));
  const glm::vec3 eye(to_glm(camera.eye));
  glUniform3fv(program.uniform("u_eye"), 1, glm::value_ptr(eye));
}

namespace {

void float_attribute(GLuint vao, GLuint location, GLuint buffer, int size) {
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
}

meshes::Mesh reorder(const meshes::Mesh& source, const std::vector<std::uint32_t>& old_of_new) {
  const std::size_t V = old_of_new.size();
  std::vector<std::uint32_t> new_of_old(source.vertex_count());
  for (std::size_t i = 0; i < source.vertex_count(); ++i)
    new_of_old[old_of_new[i]] = std::uint32_t(i);
  meshes::Mesh mesh;
  mesh.positions.resize(V);
  mesh.normals.resize(V);
  mesh.tangents.resize(V);
  mesh.bitangents.resize(V);
  for (std::size_t i = 0; i < V; ++i) {
    const std::uint32_t o = old_of_new[i];
    mesh.positions[i] = source.positions[o];
    mesh.normals[i] = source.normals[o];
    mesh.tangents[i] = source.tangents[o];
    mesh.bitangents[i] = source.bitangents[o];
  }
  mesh.triangles.resize(source.triangle_count());
  for (std::size_t t = 0; t < source.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) mesh.triangles[t][c] = new_of_old[source.triangles[t][c]];
  return mesh;
}

std::vector<std::uint32_t> flatten(const meshes::Mesh& mesh, const std::vector<std::uint32_t>& ids,
                                   bool optimize) {
  std::vector<std::uint32_t> list;
  list.reserve(ids.size() * 3);
  for (std::uint32_t t : ids)
    for (int c = 0; c < 3; ++c) list.push_back(mesh.triangles[t][c]);
  if (optimize && !list.empty()) {
    std::vector<std::uint32_t> optimised(list.size());
    meshopt_optimizeVertexCache(optimised.data(), list.data(), list.size(), mesh.vertex_count());
    list.swap(optimised);
  }
  return list;
}

}  // namespace

std::vector<std::uint32_t> first_use_rank(const meshes::Mesh& mesh, bool optimize) {
  std::vector<std::uint32_t> all(mesh.triangle_count());
  std::iota(all.begin(), all.end(), 0u);
  const std::vector<std::uint32_t> list = flatten(mesh, all, optimize);
  constexpr std::uint32_t kUnseen = ~0u;
  std::vector<std::uint32_t> rank(mesh.vertex_count(), kUnseen);
  std::uint32_t next = 0;
  for (std::uint32_t v : list)
    if (rank[v] == kUnseen) rank[v] = next++;
  for (std::uint32_t& r : rank)
    if (r == kUnseen) r = next++;
  return rank;
}

std::vector<std::uint32_t> triangle_corners(const meshes::Mesh& source,
                                            const std::vector<std::uint32_t>& triangle_ids,
                                            bool optimize) {
  return flatten(source, triangle_ids, optimize);
}

std::vector<std::uint32_t> append_vertex_block(const meshes::Mesh& source,
                                               const std::vector<std::uint32_t>& triangle_ids,
                                               bool optimize,
                                               std::vector<std::uint32_t>& old_of_new) {
  std::vector<std::uint32_t> list = flatten(source, triangle_ids, optimize);
  constexpr std::uint32_t kUnseen = ~0u;
  std::vector<std::uint32_t> copy_of(source.vertex_count(), kUnseen);
  for (std::uint32_t& v : list) {
    if (copy_of[v] == kUnseen) {
      copy_of[v] = std::uint32_t(old_of_new.size());
      old_of_new.push_back(v);
    }
    v = copy_of[v];
  }
  return list;
}

GpuMesh::GpuMesh(const meshes::Mesh& source, std::vector<std::uint32_t> old_of_new,
                 bool optimize_vertex_cache)
    : mesh_(reorder(source, old_of_new)),
      old_of_new_(std::move(old_of_new)),
      source_vertices_(source.vertex_count()),
      optimize_(optimize_vertex_cache) {
  PRTR_DCHECK(old_of_new_.size() >= source.vertex_count());
  const std::size_t V = vertex_count();
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  const GLsizeiptr vec3_bytes = GLsizeiptr(V * sizeof(float) * 3);
  const std::pair<const void*, GLuint> attributes[] = {{mesh_.positions.data(), kAttrPosition},
                                                       {mesh_.normals.data(), kAttrNormal},
                                                       {mesh_.tangents.data(), kAttrTangent}};
  for (const auto& [data, location] : attributes) {
    buffers_.push_back(make_buffer(GL_ARRAY_BUFFER, vec3_bytes, data, GL_STATIC_DRAW));
    float_attribute(vao_, location, buffers_.back(), 3);
  }
  radiance_ = make_buffer(GL_ARRAY_BUFFER, vec3_bytes, nullptr, GL_DYNAMIC_DRAW);
  float_attribute(vao_, kAttrRadiance, radiance_, 3);
  capture_ =
      make_buffer(GL_TRANSFORM_FEEDBACK_BUFFER, GLsizeiptr(V * 12), nullptr, GL_DYNAMIC_READ);
}

GpuMesh::~GpuMesh() {
  buffers_.insert(buffers_.end(), {radiance_, capture_, ibo_});
  glDeleteBuffers(GLsizei(buffers_.size()), buffers_.data());
  glDeleteVertexArrays(1, &vao_);
}

IndexRange GpuMesh::add_triangles(const std::vector<std::uint32_t>& ids) {
  IndexRange r;
  r.first = GLsizeiptr(indices_.size());
  std::vector<std::uint32_t> list = flatten(mesh_, ids, optimize_);
  indices_.insert(indices_.end(), list.begin(), list.end());
  r.count = GLsizei(list.size());
  std::sort(list.begin(), list.end());
  r.referenced = std::uint64_t(std::unique(list.begin(), list.end()) - list.begin());
  return r;
}

IndexRange GpuMesh::add_indices(const std::vector<std::uint32_t>& list) {
  IndexRange r;
  r.first = GLsizeiptr(indices_.size());
  indices_.insert(indices_.end(), list.begin(), list.end());
  r.count = GLsizei(list.size());
  std::vector<std::uint32_t> sorted = list;
  std::sort(sorted.begin(), sorted.end());
  r.referenced = std::uint64_t(std::unique(sorted.begin(), sorted.end()) - sorted.begin());
  return r;
}

IndexRange GpuMesh::add_all_triangles() {
  std::vector<std::uint32_t> all(mesh_.triangle_count());
  std::iota(all.begin(), all.end(), 0u);
  return add_triangles(all);
}

void GpuMesh::upload_indices() {
  ibo_ = make_buffer(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices_.size() * 4), indices_.data(),
                     GL_STATIC_DRAW);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo_);
  indices_.clear();
  indices_.shrink_to_fit();
  check_gl("Renderer: uploading the mesh");
}

void GpuMesh::uint_attribute(GLuint location, const std::vector<std::uint32_t>& values) {
  PRTR_DCHECK(values.size() == vertex_count());
  buffers_.push_back(
      make_buffer(GL_ARRAY_BUFFER, GLsizeiptr(values.size() * 4), values.data(), GL_STATIC_DRAW));
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, buffers_.back());
  glEnableVertexAttribArray(location);
  glVertexAttribIPointer(location, 1, GL_UNSIGNED_INT, 0, nullptr);
}

void GpuMesh::weight_attributes(const std::vector<float>& weights, int components, bool enable) {
  const int vectors = (components + 3) / 4;
  if (vectors == 0) return;
  const std::size_t V = vertex_count();
  std::vector<float> padded(V * std::size_t(vectors) * 4, 0.f);
  for (std::size_t i = 0; i < V; ++i)
    std::copy_n(weights.data() + i * components, components, padded.data() + i * vectors * 4);
  buffers_.push_back(
      make_buffer(GL_ARRAY_BUFFER, GLsizeiptr(padded.size() * 4), padded.data(), GL_STATIC_DRAW));
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, buffers_.back());
  for (int i = 0; i < vectors && enable; ++i) {
    glEnableVertexAttribArray(GLuint(kAttrWeights + i));
    glVertexAttribPointer(GLuint(kAttrWeights + i), 4, GL_FLOAT, GL_FALSE, GLsizei(vectors * 16),
                          reinterpret_cast<const void*>(std::uintptr_t(i) * 16));
  }
}

void GpuMesh::draw(const IndexRange& r) const {
  glDrawElements(GL_TRIANGLES, r.count, GL_UNSIGNED_INT,
                 reinterpret_cast<const void*>(r.first * sizeof(std::uint32_t)));
}

void GpuMesh::read(GLuint buffer, std::vector<Rgb>& into, bool add) const {
  const std::size_t V = vertex_count();
  glFinish();
  std::vector<float> data(V * 3);
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glGetBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(V * 12), data.data());
  into.resize(V, Rgb::Zero());
  for (std::size_t i = 0; i < V; ++i) {
    const Rgb v(data[i * 3], data[i * 3 + 1], data[i * 3 + 2]);
    into[i] = add ? Rgb(into[i] + v) : v;
  }
}

void GpuMesh::capture_points(std::vector<Rgb>& into, bool add) const {
  glEnable(GL_RASTERIZER_DISCARD);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, capture_);
  glBeginTransformFeedback(GL_POINTS);
  glDrawArrays(GL_POINTS, 0, GLsizei(vertex_count()));
  glEndTransformFeedback();
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
  glDisable(GL_RASTERIZER_DISCARD);
  read(capture_, into, add);
}

}  // namespace render
