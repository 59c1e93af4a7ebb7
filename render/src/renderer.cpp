#include "render/renderer.h"

#include "common/enum_names.h"
#include "gl_program.h"
#include "prt/sh_rotation.h"
#include "render/gl_context.h"
#include "render/shader_source.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>

namespace render {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Range {
  GLsizeiptr first = 0;  // in indices
  GLsizei count = 0;
};

GLuint make_buffer(GLenum target, GLsizeiptr bytes, const void* data, GLenum usage) {
  GLuint b = 0;
  glGenBuffers(1, &b);
  glBindBuffer(target, b);
  glBufferData(target, std::max<GLsizeiptr>(bytes, 16), data, usage);
  return b;
}

void float_attribute(GLuint vao, GLuint location, GLuint buffer, int size) {
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
}

void uint_attribute(GLuint vao, GLuint location, GLuint buffer) {
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glEnableVertexAttribArray(location);
  glVertexAttribIPointer(location, 1, GL_UNSIGNED_INT, 0, nullptr);
}

}  // namespace

namespace {
constexpr common::EnumName<Mode> kModeNames[] = {{Mode::kMultipass, "multipass"},
                                                 {Mode::kSinglepass, "singlepass"},
                                                 {Mode::kDecoupled, "decoupled"},
                                                 {Mode::kUncompressed, "uncompressed"},
                                                 {Mode::kCpu, "cpu"}};
}  // namespace

const char* mode_name(Mode mode) {
  return common::enum_name<Mode>(kModeNames, mode);
}

Mode parse_mode(const std::string& name) {
  return common::parse_enum<Mode>(kModeNames, name, "render mode");
}

std::vector<std::string> mode_names() {
  return common::enum_names<Mode>(kModeNames);
}

struct Renderer::Impl {
  Mode mode;
  RendererOptions options;
  RenderStats stats;
  std::size_t vertex_count = 0;

  // GPU vertex order: sorted by (pass, cluster) for the compressed GL modes, identity else.
  std::vector<std::uint32_t> old_of_new;
  meshes::Mesh mesh;  // in GPU vertex order (CPU shading reads it)
  // Compressed data in GPU order; cluster_of holds constant slots, not cluster ids.
  cpca::CompressedSet gpu_set;
  std::optional<ShadingConstants> constants;
  ConstantLayout layout;
  std::vector<std::uint32_t> slot_of;                       // cluster -> constant slot
  std::vector<GLintptr> pass_offset;                        // bytes into the constant buffer
  std::vector<std::pair<GLint, GLsizei>> cluster_vertices;  // slot order: first, count
  std::vector<GLintptr> cluster_offset;                     // bytes, same order as cluster_vertices
  int slots_per_pass = 1;
  std::vector<float> host_constants;
  const prt::TransferSet* transfer = nullptr;
  std::vector<float> exit;
  std::vector<Rgb> cpu_radiance;
  prt::ShRotation rotation{1, Eigen::Matrix3d::Identity()};
  Eigen::MatrixXd lit;

  // GL objects.
  GLuint vao = 0, empty_vao = 0;
  GLuint vbo_position = 0, vbo_normal = 0, vbo_tangent = 0, vbo_cluster = 0, vbo_pass = 0,
         vbo_weights = 0, vbo_radiance = 0, ibo = 0, constant_buffer = 0, exit_buffer = 0,
         capture_buffer = 0;
  GLuint probe_texture = 0;
  GLuint fbo = 0, colour_rb = 0, depth_rb = 0;
  int fbo_width = 0, fbo_height = 0;
  std::vector<GLuint> queries;
  Range whole;
  std::vector<Range> pass_ranges;
  GlProgram depth_program, shade_program, passthrough_program, background_program;
  Background background;
  bool have_probe = false;

  ~Impl() {
    GLuint buffers[] = {vbo_position,    vbo_normal,  vbo_tangent,   vbo_cluster,
                        vbo_pass,        vbo_weights, vbo_radiance,  ibo,
                        constant_buffer, exit_buffer, capture_buffer};
    glDeleteBuffers(GLsizei(std::size(buffers)), buffers);
    glDeleteVertexArrays(1, &vao);
    glDeleteVertexArrays(1, &empty_vao);
    glDeleteTextures(1, &probe_texture);
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &colour_rb);
    glDeleteRenderbuffers(1, &depth_rb);
    if (!queries.empty()) glDeleteQueries(GLsizei(queries.size()), queries.data());
  }

  bool compressed_gl() const {
    return mode == Mode::kMultipass || mode == Mode::kSinglepass || mode == Mode::kDecoupled;
  }

  void setup(const meshes::Mesh& source, const cpca::CompressedSet* set,
             const prt::TransferSet* transfer_set, const probes::Probe* probe);
  void build_groups(const cpca::CompressedSet& set, const meshes::Mesh& source,
                    cpca::SuperClusters& groups, std::vector<std::vector<std::uint32_t>>& lists);
  void upload_mesh(const meshes::Mesh& source, const cpca::CompressedSet* set,
                   const cpca::SuperClusters& groups,
                   const std::vector<std::vector<std::uint32_t>>& lists);
  void ensure_framebuffer(int width, int height);
  void update(const Camera& camera, const Eigen::Ref<const prt::ShLighting>& lighting,
              const Eigen::Matrix3d& rotation_matrix);
  void set_camera_uniforms(GlProgram& program, const Camera& camera);
  void shade_decoupled();
  void draw(const Camera& camera, const Eigen::Matrix3d& rotation_matrix);
  void draw_background(const Camera& camera, const Eigen::Matrix3d& rotation_matrix);
  void draw_range(const Range& r) const {
    glDrawElements(GL_TRIANGLES, r.count, GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(r.first * sizeof(std::uint32_t)));
  }
};

void Renderer::Impl::build_groups(const cpca::CompressedSet& set, const meshes::Mesh& source,
                                  cpca::SuperClusters& groups,
                                  std::vector<std::vector<std::uint32_t>>& lists) {
  const int registers = layout.registers_per_cluster();
  GLint align = 16;
  glGetIntegerv(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, &align);
  const int context_budget = current_gl_info().default_register_budget();
  int budget = options.register_budget > 0 ? options.register_budget : context_budget;
  if (budget > context_budget)
    throw std::invalid_argument("--register-budget " + std::to_string(budget) +
                                " exceeds what the GL context offers (" +
                                std::to_string(context_budget) + " vec4); lower it");
  if (budget < registers)
    throw std::invalid_argument(
        "--register-budget " + std::to_string(budget) + " is below one cluster's " +
        std::to_string(registers) + " vec4 (order " + std::to_string(set.order) + ", " +
        std::to_string(set.component_count) + " PCs); raise it or use fewer PCs");
  int per_pass = budget / registers;
  if (options.clusters_per_pass > 0) {
    if (options.clusters_per_pass > per_pass)
      throw std::invalid_argument(
          "--clusters-per-pass " + std::to_string(options.clusters_per_pass) + " needs " +
          std::to_string(options.clusters_per_pass * registers) + " vec4 but the budget is " +
          std::to_string(budget) + "; lower it or raise --register-budget");
    per_pass = options.clusters_per_pass;
  }
  stats.register_budget = budget;
  stats.registers_per_cluster = registers;

  const bool split = mode == Mode::kMultipass || mode == Mode::kDecoupled;
  if (options.groups && split) {
    groups = *options.groups;
    groups.pass_of = cpca::pass_of_clusters(groups, set.cluster_count);
    for (std::size_t p = 0; p < groups.passes.size(); ++p)
      if (int(groups.passes[p].size()) > per_pass)
        throw std::invalid_argument("super-cluster " + std::to_string(p) + " holds " +
                                    std::to_string(groups.passes[p].size()) +
                                    " clusters but a pass fits " + std::to_string(per_pass) +
                                    " within the register budget");
  } else {
    groups =
        cpca::group_in_order(set.cluster_count, split ? per_pass : std::max(1, set.cluster_count));
  }
  int max_in_pass = 1;
  for (const auto& pass : groups.passes) max_in_pass = std::max(max_in_pass, int(pass.size()));
  slots_per_pass = max_in_pass;
  stats.clusters_per_pass = split ? per_pass : set.cluster_count;

  // Constant slots: pass by pass, each pass starting at an aligned offset (its UBO range);
  // decoupled binds every cluster on its own, so each cluster is aligned.
  const GLintptr cluster_bytes = GLintptr(registers) * 16;
  auto aligned = [&](int slot) {
    while ((GLintptr(slot) * cluster_bytes) % align != 0) ++slot;
    return slot;
  };
  slot_of.assign(std::size_t(set.cluster_count), 0);
  int next = 0;
  for (const auto& pass : groups.passes) {
    next = aligned(next);
    pass_offset.push_back(GLintptr(next) * cluster_bytes);
    for (std::uint32_t k : pass) {
      if (mode == Mode::kDecoupled) next = aligned(next);
      slot_of[k] = std::uint32_t(next++);
    }
  }
  // Room for a full-size range from the last pass's start.
  const int total_slots = next + slots_per_pass;
  host_constants.assign(std::size_t(total_slots) * layout.floats_stride(), 0.f);

  std::vector<cpca::TriangleIndices> tris(source.triangles.begin(), source.triangles.end());
  if (mode == Mode::kMultipass) {
    lists = cpca::triangles_per_pass(set.cluster_of, tris, groups);
    const cpca::OverdrawStats od = cpca::overdraw(set.cluster_of, tris, groups);
    stats.triangles_per_pass = od.triangles_per_pass;
    stats.average_overdraw = od.average_overdraw;
    stats.passes = int(groups.passes.size());
  }
}

void Renderer::Impl::upload_mesh(const meshes::Mesh& source, const cpca::CompressedSet* set,
                                 const cpca::SuperClusters& groups,
                                 const std::vector<std::vector<std::uint32_t>>& lists) {
  const std::size_t V = source.vertex_count();
  old_of_new.resize(V);
  std::iota(old_of_new.begin(), old_of_new.end(), 0u);
  if (compressed_gl()) {
    std::stable_sort(old_of_new.begin(), old_of_new.end(), [&](std::uint32_t a, std::uint32_t b) {
      return slot_of[set->cluster_of[a]] < slot_of[set->cluster_of[b]];
    });
  }
  std::vector<std::uint32_t> new_of_old(V);
  for (std::size_t i = 0; i < V; ++i) new_of_old[old_of_new[i]] = std::uint32_t(i);

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

  std::vector<std::uint32_t> pass_of_vertex(V, 0), cluster_attr(V, 0);
  if (set) {
    const int N = set->component_count;
    gpu_set.component_count = N;
    gpu_set.cluster_of.resize(V);
    gpu_set.weights.resize(V * std::size_t(N));
    for (std::size_t i = 0; i < V; ++i) {
      const std::uint32_t o = old_of_new[i];
      const std::uint32_t k = set->cluster_of[o];
      gpu_set.cluster_of[i] = slot_of[k];
      std::copy_n(set->weights.data() + o * std::size_t(N), N,
                  gpu_set.weights.data() + i * std::size_t(N));
      if (!groups.pass_of.empty()) pass_of_vertex[i] = groups.pass_of[k];
      cluster_attr[i] =
          mode == Mode::kMultipass
              ? std::uint32_t(slot_of[k] - pass_offset[pass_of_vertex[i]] /
                                               (GLintptr(layout.registers_per_cluster()) * 16))
              : slot_of[k];
    }
    // Vertex ranges of each cluster, in slot order, for the decoupled draws.
    std::vector<std::uint32_t> clusters_by_slot(set->cluster_count);
    std::iota(clusters_by_slot.begin(), clusters_by_slot.end(), 0u);
    std::sort(clusters_by_slot.begin(), clusters_by_slot.end(),
              [&](std::uint32_t a, std::uint32_t b) { return slot_of[a] < slot_of[b]; });
    std::size_t v = 0;
    for (std::uint32_t k : clusters_by_slot) {
      const std::size_t first = v;
      while (v < V && gpu_set.cluster_of[v] == slot_of[k]) ++v;
      if (v > first) {
        cluster_vertices.emplace_back(GLint(first), GLsizei(v - first));
        cluster_offset.push_back(GLintptr(slot_of[k]) * layout.registers_per_cluster() * 16);
      }
    }
  }

  // Index buffers: the whole mesh, then each pass's triangles, each in vertex-cache order.
  std::vector<std::uint32_t> indices;
  auto append = [&](const std::vector<std::uint32_t>& triangle_ids) {
    Range r;
    r.first = GLsizeiptr(indices.size());
    std::vector<std::uint32_t> list;
    list.reserve(triangle_ids.size() * 3);
    for (std::uint32_t t : triangle_ids)
      for (int c = 0; c < 3; ++c) list.push_back(mesh.triangles[t][c]);
    if (options.optimize_vertex_cache && !list.empty()) {
      std::vector<std::uint32_t> optimised(list.size());
      meshopt_optimizeVertexCache(optimised.data(), list.data(), list.size(), V);
      list.swap(optimised);
    }
    indices.insert(indices.end(), list.begin(), list.end());
    r.count = GLsizei(list.size());
    return r;
  };
  std::vector<std::uint32_t> all(source.triangle_count());
  std::iota(all.begin(), all.end(), 0u);
  whole = append(all);
  for (const auto& list : lists) pass_ranges.push_back(append(list));
  if (mode != Mode::kMultipass) {
    stats.passes = 1;
    stats.triangles_per_pass = {source.triangle_count()};
    stats.average_overdraw = 1.0;
  }

  glGenVertexArrays(1, &vao);
  glGenVertexArrays(1, &empty_vao);
  glBindVertexArray(vao);
  const GLsizeiptr vec3_bytes = GLsizeiptr(V * sizeof(float) * 3);
  vbo_position = make_buffer(GL_ARRAY_BUFFER, vec3_bytes, mesh.positions.data(), GL_STATIC_DRAW);
  float_attribute(vao, kAttrPosition, vbo_position, 3);
  vbo_normal = make_buffer(GL_ARRAY_BUFFER, vec3_bytes, mesh.normals.data(), GL_STATIC_DRAW);
  float_attribute(vao, kAttrNormal, vbo_normal, 3);
  vbo_tangent = make_buffer(GL_ARRAY_BUFFER, vec3_bytes, mesh.tangents.data(), GL_STATIC_DRAW);
  float_attribute(vao, kAttrTangent, vbo_tangent, 3);
  vbo_radiance = make_buffer(GL_ARRAY_BUFFER, vec3_bytes, nullptr, GL_DYNAMIC_DRAW);
  float_attribute(vao, kAttrRadiance, vbo_radiance, 3);
  if (set) {
    vbo_cluster =
        make_buffer(GL_ARRAY_BUFFER, GLsizeiptr(V * 4), cluster_attr.data(), GL_STATIC_DRAW);
    uint_attribute(vao, kAttrCluster, vbo_cluster);
    vbo_pass =
        make_buffer(GL_ARRAY_BUFFER, GLsizeiptr(V * 4), pass_of_vertex.data(), GL_STATIC_DRAW);
    uint_attribute(vao, kAttrPass, vbo_pass);
    const int N = set->component_count;
    const int vectors = (N + 3) / 4;
    if (compressed_gl() && kAttrWeights + vectors > kAttrRadiance)
      throw std::invalid_argument(std::to_string(N) + " PCs need " + std::to_string(vectors) +
                                  " weight attributes but the GL context offers " +
                                  std::to_string(kAttrRadiance - kAttrWeights) +
                                  " (at most 40 PCs)" + "; compress with fewer PCs");
    if (vectors > 0) {
      std::vector<float> padded(V * std::size_t(vectors) * 4, 0.f);
      for (std::size_t i = 0; i < V; ++i)
        std::copy_n(gpu_set.weights.data() + i * N, N, padded.data() + i * vectors * 4);
      vbo_weights = make_buffer(GL_ARRAY_BUFFER, GLsizeiptr(padded.size() * 4), padded.data(),
                                GL_STATIC_DRAW);
      glBindVertexArray(vao);
      glBindBuffer(GL_ARRAY_BUFFER, vbo_weights);
      for (int i = 0; i < vectors && compressed_gl(); ++i) {
        glEnableVertexAttribArray(GLuint(kAttrWeights + i));
        glVertexAttribPointer(GLuint(kAttrWeights + i), 4, GL_FLOAT, GL_FALSE,
                              GLsizei(vectors * 16), reinterpret_cast<const void*>(i * 16));
      }
    }
  }
  ibo = make_buffer(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * 4), indices.data(),
                    GL_STATIC_DRAW);
  glBindVertexArray(vao);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
  check_gl("Renderer: uploading the mesh");
}

void Renderer::Impl::setup(const meshes::Mesh& source, const cpca::CompressedSet* set,
                           const prt::TransferSet* transfer_set, const probes::Probe* probe) {
  if (!source.has_frames())
    throw std::invalid_argument(
        "Renderer: the mesh has no tangent frames; run meshes::compute_frames");
  vertex_count = source.vertex_count();
  stats.vertex_count = vertex_count;
  stats.triangle_count = source.triangle_count();
  int order = 0;
  bool glossy = true;
  if (mode == Mode::kUncompressed) {
    if (!transfer_set)
      throw std::invalid_argument("uncompressed mode needs the transfer file (--transfer PRTX)");
    if (transfer_set->vertex_count != vertex_count)
      throw std::invalid_argument("the transfer set has " +
                                  std::to_string(transfer_set->vertex_count) +
                                  " vertices but the mesh has " + std::to_string(vertex_count) +
                                  "; use the mesh it was baked from");
    transfer = transfer_set;
    order = transfer->order;
    glossy = transfer->kind == prt::TransferKind::kGlossy;
  } else {
    if (!set)
      throw std::invalid_argument("mode " + std::string(mode_name(mode)) +
                                  " needs a compressed set");
    cpca::validate(*set);
    if (set->vertex_count != vertex_count)
      throw std::invalid_argument("the compressed set has " + std::to_string(set->vertex_count) +
                                  " vertices but the mesh has " + std::to_string(vertex_count) +
                                  "; use the mesh it was baked from");
    constants.emplace(*set);
    layout = constants->layout();
    order = set->order;
    glossy = set->glossy();
  }
  rotation = prt::ShRotation(order, Eigen::Matrix3d::Identity());
  lit.resize(order * order, 3);

  cpca::SuperClusters groups;
  std::vector<std::vector<std::uint32_t>> lists;
  if (set && mode != Mode::kUncompressed)
    build_groups(*set, source, groups, lists);
  else {
    stats.registers_per_cluster = 0;
    slot_of.clear();
  }
  upload_mesh(source, mode == Mode::kUncompressed ? nullptr : set, groups, lists);

  // Programs.
  depth_program = GlProgram("depth pre-pass", position_vertex_shader(), coverage_fragment_shader());
  passthrough_program =
      GlProgram("pass-through", passthrough_vertex_shader(), radiance_fragment_shader(), true);
  background_program =
      GlProgram("background", background_vertex_shader(), background_fragment_shader());
  switch (mode) {
    case Mode::kMultipass:
      shade_program = GlProgram(
          "multipass shading",
          compressed_vertex_shader(layout, ConstantAccess::kUniformSlot, slots_per_pass, true),
          radiance_fragment_shader(), true);
      break;
    case Mode::kSinglepass:
      shade_program =
          GlProgram("single-pass shading",
                    compressed_vertex_shader(layout, ConstantAccess::kStorage, 0, false),
                    radiance_fragment_shader(), true);
      break;
    case Mode::kDecoupled:
      shade_program =
          GlProgram("decoupled shading",
                    compressed_vertex_shader(layout, ConstantAccess::kUniformFixed, 1, false),
                    radiance_fragment_shader(), true);
      break;
    case Mode::kUncompressed:
      shade_program = GlProgram("uncompressed shading", uncompressed_vertex_shader(order, glossy),
                                radiance_fragment_shader(), true);
      break;
    case Mode::kCpu:
      break;
  }

  if (compressed_gl() || mode == Mode::kCpu) {
    const GLenum target = mode == Mode::kSinglepass ? GL_SHADER_STORAGE_BUFFER : GL_UNIFORM_BUFFER;
    constant_buffer =
        make_buffer(target, GLsizeiptr(host_constants.size() * 4), nullptr, GL_DYNAMIC_DRAW);
  }
  if (mode == Mode::kUncompressed)
    exit_buffer = make_buffer(GL_SHADER_STORAGE_BUFFER,
                              GLsizeiptr(vertex_count * 3 * (glossy ? order * order : 1) * 4),
                              nullptr, GL_DYNAMIC_DRAW);
  capture_buffer = make_buffer(GL_TRANSFORM_FEEDBACK_BUFFER, GLsizeiptr(vertex_count * 12), nullptr,
                               GL_DYNAMIC_READ);

  glGenTextures(1, &probe_texture);
  glBindTexture(GL_TEXTURE_2D, probe_texture);
  std::vector<float> texels;
  int tw = 2, th = 1;
  if (probe && probe->width() > 0) {
    tw = probe->width();
    th = probe->height();
    texels.assign(std::size_t(tw) * th * 4, 1.f);
    for (std::size_t i = 0; i < probe->texels().size(); ++i)
      for (int c = 0; c < 3; ++c) texels[i * 4 + c] = probe->texels()[i][c];
    have_probe = true;
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
  background.use_probe = have_probe;
  check_gl("Renderer: set-up");
}

void Renderer::Impl::ensure_framebuffer(int width, int height) {
  if (fbo && width == fbo_width && height == fbo_height) return;
  if (!fbo) {
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(1, &colour_rb);
    glGenRenderbuffers(1, &depth_rb);
  }
  glBindRenderbuffer(GL_RENDERBUFFER, colour_rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, width, height);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_rb);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_rb);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw GlError("framebuffer " + std::to_string(width) + " x " + std::to_string(height) +
                  " RGBA32F + depth is incomplete (status " + std::to_string(status) +
                  "); try a smaller --width/--height");
  check_gl("Renderer: framebuffer");
  fbo_width = width;
  fbo_height = height;
}

void Renderer::Impl::update(const Camera& camera, const Eigen::Ref<const prt::ShLighting>& lighting,
                            const Eigen::Matrix3d& rotation_matrix) {
  if (lighting.rows() != lit.rows())
    throw std::invalid_argument("lighting has " + std::to_string(lighting.rows()) +
                                " SH rows; the data is order " + std::to_string(rotation.order()) +
                                " (" + std::to_string(lit.rows()) +
                                " rows): project the probe at that order");
  rotation.set(rotation_matrix);
  rotation.apply(lighting, lit);
  if (mode == Mode::kUncompressed) {
    exit_vectors(*transfer, lit, exit);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, exit_buffer);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, GLsizeiptr(exit.size() * 4), exit.data());
    return;
  }
  constants->compute(lit, slot_of, host_constants.data());
  if (mode == Mode::kCpu) {
    shade_vertices(gpu_set, layout, host_constants.data(), mesh, camera.eye, cpu_radiance);
    glBindBuffer(GL_ARRAY_BUFFER, vbo_radiance);
    glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(cpu_radiance.size() * 12), cpu_radiance.data());
    return;
  }
  const GLenum target = mode == Mode::kSinglepass ? GL_SHADER_STORAGE_BUFFER : GL_UNIFORM_BUFFER;
  glBindBuffer(target, constant_buffer);
  glBufferSubData(target, 0, GLsizeiptr(host_constants.size() * 4), host_constants.data());
}

void Renderer::Impl::set_camera_uniforms(GlProgram& program, const Camera& camera) {
  program.use();
  const Eigen::Matrix4f clip = camera.clip_from_world().cast<float>();
  glUniformMatrix4fv(program.uniform("u_clip_from_world"), 1, GL_FALSE, clip.data());
  const Eigen::Vector3f eye = camera.eye.cast<float>();
  glUniform3fv(program.uniform("u_eye"), 1, eye.data());
}

void Renderer::Impl::shade_decoupled() {
  // Every cluster's vertices form one contiguous range in slot order, so transform feedback
  // appends them exactly at their own vertex index.
  shade_program.use();
  glEnable(GL_RASTERIZER_DISCARD);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, vbo_radiance);
  glBeginTransformFeedback(GL_POINTS);
  const GLsizeiptr bytes = GLsizeiptr(layout.registers_per_cluster()) * 16;
  for (std::size_t i = 0; i < cluster_vertices.size(); ++i) {
    glBindBufferRange(GL_UNIFORM_BUFFER, kConstantsBinding, constant_buffer, cluster_offset[i],
                      bytes);
    glDrawArrays(GL_POINTS, cluster_vertices[i].first, cluster_vertices[i].second);
  }
  glEndTransformFeedback();
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
  glDisable(GL_RASTERIZER_DISCARD);
}

void Renderer::Impl::draw(const Camera& camera, const Eigen::Matrix3d& rotation_matrix) {
  ensure_framebuffer(camera.width, camera.height);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, camera.width, camera.height);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  // A solid background is the clear colour (alpha 0: not coverage); the multipass pre-pass
  // writes (0, 0, 0, 1) over it wherever the mesh is, so the additive passes start at zero.
  const bool probe_background = background.use_probe && have_probe;
  const Rgb clear = probe_background ? Rgb::Zero() : background.colour;
  glClearColor(clear.x(), clear.y(), clear.z(), 0.f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  if (options.cull_back_faces) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
  } else {
    glDisable(GL_CULL_FACE);
  }
  glBindVertexArray(vao);
  const bool count = options.count_primitives;
  if (count && queries.size() < pass_ranges.size() + 1) {
    if (!queries.empty()) glDeleteQueries(GLsizei(queries.size()), queries.data());
    queries.assign(pass_ranges.size() + 1, 0);
    glGenQueries(GLsizei(queries.size()), queries.data());
  }

  if (mode == Mode::kMultipass) {
    set_camera_uniforms(depth_program, camera);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);  // rgb = 0, alpha = coverage
    glDepthFunc(GL_LESS);
    draw_range(whole);
    set_camera_uniforms(shade_program, camera);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_FALSE);
    glDepthFunc(GL_EQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    const GLsizeiptr bytes = GLsizeiptr(slots_per_pass) * layout.registers_per_cluster() * 16;
    for (std::size_t p = 0; p < pass_ranges.size(); ++p) {
      if (pass_ranges[p].count == 0) continue;
      glUniform1ui(shade_program.uniform("u_pass"), GLuint(p));
      glBindBufferRange(GL_UNIFORM_BUFFER, kConstantsBinding, constant_buffer, pass_offset[p],
                        bytes);
      if (count) glBeginQuery(GL_PRIMITIVES_GENERATED, queries[p]);
      draw_range(pass_ranges[p]);
      if (count) glEndQuery(GL_PRIMITIVES_GENERATED);
    }
    glDisable(GL_BLEND);
  } else {
    GlProgram* program = &shade_program;
    if (mode == Mode::kSinglepass) {
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kConstantsBinding, constant_buffer);
    } else if (mode == Mode::kUncompressed) {
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kExitBinding, exit_buffer);
    } else if (mode == Mode::kDecoupled) {
      set_camera_uniforms(shade_program, camera);
      shade_decoupled();
      program = &passthrough_program;
    } else {
      program = &passthrough_program;
    }
    set_camera_uniforms(*program, camera);
    glDepthFunc(GL_LESS);
    if (count) glBeginQuery(GL_PRIMITIVES_GENERATED, queries[0]);
    draw_range(whole);
    if (count) glEndQuery(GL_PRIMITIVES_GENERATED);
  }

  // Background where no triangle wrote depth (depth is still the cleared 1.0).
  if (probe_background) draw_background(camera, rotation_matrix);
  glDepthMask(GL_TRUE);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glBindVertexArray(vao);
}

void Renderer::Impl::draw_background(const Camera& camera, const Eigen::Matrix3d& rotation_matrix) {
  glBindVertexArray(empty_vao);
  background_program.use();
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_FALSE);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
  const Eigen::Vector3d f = (camera.target - camera.eye).normalized();
  const Eigen::Vector3d r = f.cross(camera.up).normalized();
  const Eigen::Vector3d u = r.cross(f);
  const double t = std::tan(0.5 * camera.fov_y_degrees * std::numbers::pi / 180.0);
  const Eigen::Vector3f ff = f.cast<float>(), rr = (r * t * camera.aspect()).cast<float>(),
                        uu = (u * t).cast<float>();
  glUniform3fv(background_program.uniform("u_forward"), 1, ff.data());
  glUniform3fv(background_program.uniform("u_right"), 1, rr.data());
  glUniform3fv(background_program.uniform("u_up"), 1, uu.data());
  const Eigen::Matrix3f probe_from_world = rotation_matrix.transpose().cast<float>();
  glUniformMatrix3fv(background_program.uniform("u_probe_from_world"), 1, GL_FALSE,
                     probe_from_world.data());
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, probe_texture);
  glUniform1i(background_program.uniform("u_probe"), 0);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

Renderer::Renderer(const meshes::Mesh& mesh, const cpca::CompressedSet* set,
                   const prt::TransferSet* transfer, const probes::Probe* probe,
                   const RendererOptions& options)
    : impl_(std::make_unique<Impl>()) {
  impl_->mode = options.mode;
  impl_->options = options;
  impl_->setup(mesh, set, transfer, probe);
}

Renderer::~Renderer() = default;

void Renderer::set_background(const Background& background) {
  impl_->background = background;
}

FrameTiming Renderer::render(const Camera& camera,
                             const Eigen::Ref<const prt::ShLighting>& lighting,
                             const Eigen::Matrix3d& rotation) {
  camera.validate();
  FrameTiming timing;
  const auto start = Clock::now();
  impl_->update(camera, lighting, rotation);
  timing.cpu_ms = ms_since(start);
  const auto gl_start = Clock::now();
  impl_->draw(camera, rotation);
  glFinish();
  timing.gl_ms = ms_since(gl_start);
  timing.total_ms = ms_since(start);
  if (impl_->options.count_primitives) {
    RenderStats& s = impl_->stats;
    s.measured_triangles.clear();
    const std::size_t n = impl_->mode == Mode::kMultipass ? impl_->pass_ranges.size() : 1;
    for (std::size_t p = 0; p < n; ++p) {
      GLuint value = 0;  // libOSMesa exports the 32-bit query getter only
      if (impl_->mode != Mode::kMultipass || impl_->pass_ranges[p].count > 0)
        glGetQueryObjectuiv(impl_->queries[p], GL_QUERY_RESULT, &value);
      s.measured_triangles.push_back(value);
    }
  }
  check_gl("Renderer::render");
  return timing;
}

Image Renderer::read_image() const {
  Image image;
  image.width = impl_->fbo_width;
  image.height = impl_->fbo_height;
  if (!impl_->fbo) throw GlError("Renderer::read_image: nothing rendered yet; call render() first");
  image.rgba.resize(std::size_t(image.width) * image.height * 4);
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<float> rows(image.rgba.size());
  glReadPixels(0, 0, image.width, image.height, GL_RGBA, GL_FLOAT, rows.data());
  check_gl("Renderer::read_image");
  const std::size_t row = std::size_t(image.width) * 4;
  for (int y = 0; y < image.height; ++y)
    std::copy_n(rows.data() + std::size_t(image.height - 1 - y) * row, row,
                image.rgba.data() + std::size_t(y) * row);
  return image;
}

std::vector<Rgb> Renderer::capture_vertex_radiance(
    const Camera& camera, const Eigen::Ref<const prt::ShLighting>& lighting,
    const Eigen::Matrix3d& rotation) {
  Impl& m = *impl_;
  m.update(camera, lighting, rotation);
  const std::size_t V = m.vertex_count;
  std::vector<Rgb> gpu(V, Rgb::Zero());
  glBindVertexArray(m.vao);
  auto read = [&](GLuint buffer, std::vector<Rgb>& into, bool add) {
    glFinish();
    std::vector<float> data(V * 3);
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    glGetBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(V * 12), data.data());
    for (std::size_t i = 0; i < V; ++i) {
      const Rgb v(data[i * 3], data[i * 3 + 1], data[i * 3 + 2]);
      into[i] = add ? Rgb(into[i] + v) : v;
    }
  };
  auto capture_points = [&](GLuint pass, bool add) {
    glEnable(GL_RASTERIZER_DISCARD);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, m.capture_buffer);
    glBeginTransformFeedback(GL_POINTS);
    if (m.mode == Mode::kMultipass) glUniform1ui(m.shade_program.uniform("u_pass"), pass);
    glDrawArrays(GL_POINTS, 0, GLsizei(V));
    glEndTransformFeedback();
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
    glDisable(GL_RASTERIZER_DISCARD);
    read(m.capture_buffer, gpu, add);
  };
  switch (m.mode) {
    case Mode::kMultipass: {
      m.set_camera_uniforms(m.shade_program, camera);
      const GLsizeiptr bytes = GLsizeiptr(m.slots_per_pass) * m.layout.registers_per_cluster() * 16;
      for (std::size_t p = 0; p < m.pass_offset.size(); ++p) {
        glBindBufferRange(GL_UNIFORM_BUFFER, kConstantsBinding, m.constant_buffer, m.pass_offset[p],
                          bytes);
        capture_points(GLuint(p), true);
      }
      break;
    }
    case Mode::kSinglepass:
      m.set_camera_uniforms(m.shade_program, camera);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kConstantsBinding, m.constant_buffer);
      capture_points(0, false);
      break;
    case Mode::kUncompressed:
      m.set_camera_uniforms(m.shade_program, camera);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kExitBinding, m.exit_buffer);
      capture_points(0, false);
      break;
    case Mode::kDecoupled:
      m.set_camera_uniforms(m.shade_program, camera);
      m.shade_decoupled();
      read(m.vbo_radiance, gpu, false);
      break;
    case Mode::kCpu:
      gpu = m.cpu_radiance;
      break;
  }
  check_gl("Renderer::capture_vertex_radiance");
  std::vector<Rgb> out(V);
  for (std::size_t i = 0; i < V; ++i) out[m.old_of_new[i]] = gpu[i];
  return out;
}

const RenderStats& Renderer::stats() const {
  return impl_->stats;
}

Mode Renderer::mode() const {
  return impl_->mode;
}

TimingSummary measure(Renderer& renderer, const Camera& camera,
                      const Eigen::Ref<const prt::ShLighting>& lighting,
                      const Eigen::Matrix3d& start_rotation, const Eigen::Vector3d& axis,
                      double degrees_per_frame, int frames, int warmup) {
  if (frames < 1) throw std::invalid_argument("--frames must be >= 1");
  std::vector<double> total, cpu, gl;
  for (int f = -warmup; f < frames; ++f) {
    const Eigen::Matrix3d r = prt::axis_angle(axis.normalized(), degrees_per_frame * (f + warmup) *
                                                                     std::numbers::pi / 180.0) *
                              start_rotation;
    const FrameTiming t = renderer.render(camera, lighting, r);
    if (f < 0) continue;
    total.push_back(t.total_ms);
    cpu.push_back(t.cpu_ms);
    gl.push_back(t.gl_ms);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  TimingSummary s;
  s.frames = frames;
  s.frame_ms_median = median(total);
  s.cpu_ms_median = median(cpu);
  s.gl_ms_median = median(gl);
  s.fps = s.frame_ms_median > 0 ? 1000.0 / s.frame_ms_median : 0.0;
  return s;
}

}  // namespace render
