// The paths that shade from CPCA constants (render/renderer.h): multipass, single-pass,
// decoupled and CPU. They share the constant slots (cluster -> offset in one buffer), the
// per-frame constants (render/shading.h) and the per-vertex cluster data; they differ in how
// clusters are grouped into passes, how the constants are bound and who shades.
#include "common/check.h"
#include "gpu_constants.h"
#include "render/gl_context.h"
#include "render/pass_capacity.h"
#include "render/shader_source.h"
#include "render_path.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace render {
namespace {

// Where each cluster's constants live: slots of registers_per_cluster vec4, pass by pass,
// each pass starting at a UBO-aligned offset (its range); `per_cluster_aligned` aligns every
// cluster (decoupled binds each on its own).
struct SlotPlan {
  cpca::SuperClusters groups;
  std::vector<std::uint32_t> slot_of;  // cluster -> slot
  std::vector<GLintptr> pass_offset;   // bytes
  int slots_per_pass = 1;
  int total_slots = 0;  // with room for a full-size range from the last pass's start
};

// A transform-feedback session writing the radiance buffer. Attribute 15 reads that buffer,
// and a buffer both bound for feedback and enabled as a vertex source is undefined (GL 4.5
// core, 13.2.2), so the attribute is off while the buffer is written.
void begin_radiance_feedback(GpuMesh& mesh) {
  glEnable(GL_RASTERIZER_DISCARD);
  mesh.bind();
  glDisableVertexAttribArray(kAttrRadiance);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, mesh.radiance_buffer());
  glBeginTransformFeedback(GL_POINTS);
}

void end_radiance_feedback() {
  glEndTransformFeedback();
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
  glEnableVertexAttribArray(kAttrRadiance);
  glDisable(GL_RASTERIZER_DISCARD);
}

// The clusters one pass holds (render/pass_capacity.h refuses what does not fit); records the
// budget and the cost in the stats.
int clusters_per_pass(const PathInput& in) {
  const PassCapacity capacity =
      pass_capacity(*in.set, in.options.register_budget,
                    current_gl_info().default_register_budget(), in.options.clusters_per_pass);
  in.stats.register_budget = capacity.register_budget;
  in.stats.registers_per_cluster = capacity.registers_per_cluster;
  return capacity.clusters_per_pass;
}

// The grouping: the caller's (checked against the capacity) for the paths that split, else
// clusters in order.
cpca::SuperClusters group(const PathInput& in, int per_pass, bool split) {
  const int K = in.set->cluster_count;
  in.stats.clusters_per_pass = split ? per_pass : K;
  if (!in.options.groups || !split)
    return cpca::group_in_order(K, split ? per_pass : std::max(1, K));
  cpca::SuperClusters groups = *in.options.groups;
  groups.pass_of = cpca::pass_of_clusters(groups, K);
  for (std::size_t p = 0; p < groups.passes.size(); ++p)
    if (int(groups.passes[p].size()) > per_pass)
      throw std::invalid_argument("super-cluster " + std::to_string(p) + " holds " +
                                  std::to_string(groups.passes[p].size()) +
                                  " clusters but a pass fits " + std::to_string(per_pass) +
                                  " within the register budget");
  return groups;
}

SlotPlan plan_slots(cpca::SuperClusters groups, int cluster_count, int registers,
                    bool per_cluster_aligned) {
  GLint align = 16;
  glGetIntegerv(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, &align);
  SlotPlan plan;
  for (const auto& pass : groups.passes)
    plan.slots_per_pass = std::max(plan.slots_per_pass, int(pass.size()));
  const GLintptr cluster_bytes = GLintptr(registers) * 16;
  auto aligned = [&](int slot) {
    while ((GLintptr(slot) * cluster_bytes) % align != 0) ++slot;
    return slot;
  };
  plan.slot_of.assign(std::size_t(cluster_count), 0);
  int next = 0;
  for (const auto& pass : groups.passes) {
    next = aligned(next);
    plan.pass_offset.push_back(GLintptr(next) * cluster_bytes);
    for (std::uint32_t k : pass) {
      if (per_cluster_aligned) next = aligned(next);
      plan.slot_of[k] = std::uint32_t(next++);
    }
  }
  plan.total_slots = next + plan.slots_per_pass;
  plan.groups = std::move(groups);
  return plan;
}

// What every cluster path shares: the slot plan, constants and their buffer, the GPU mesh
// with per-vertex slot, pass and weights.
class ClusterPath : public RenderPath {
 public:
  // `sort_by_slot`: store vertices sorted by constant slot (each cluster one vertex range),
  // in first-use order within a slot. `pass_blocks`: after the whole mesh, a block of copies
  // per pass of the vertices its triangles reference, each in the pass's own first-use order,
  // so every pass draws consecutive indices (pass_lists_).
  // `zero_copies` (with `sort_by_slot`, instead of pass blocks): each pass's index list names
  // its own corners by their mesh vertex and other passes' corners by one appended copy per
  // vertex whose radiance stays zero (zero_copy_lists_).
  // `legacy_sort`: the slot sort this path had before renumbering (renumber_vertices off).
  ClusterPath(const PathInput& in, bool split, bool per_cluster_aligned, bool sort_by_slot,
              bool pass_blocks, bool legacy_sort, bool zero_copies = false)
      : constants_(*in.set), layout_(constants_.layout()) {
    const int per_pass = clusters_per_pass(in);
    plan_ = plan_slots(group(in, per_pass, split), in.set->cluster_count,
                       layout_.registers_per_cluster(), per_cluster_aligned);
    host_.assign(std::size_t(plan_.total_slots) * layout_.floats_stride(), 0.f);
    const bool optimize = in.options.optimize_vertex_cache;
    const bool renumber = in.options.renumber_vertices;
    std::vector<std::uint32_t> order =
        vertex_order(in.mesh, *in.set, renumber ? sort_by_slot : legacy_sort, optimize, renumber);
    if (pass_blocks) {
      std::vector<cpca::TriangleIndices> tris(in.mesh.triangles.begin(), in.mesh.triangles.end());
      for (const auto& ids : cpca::triangles_per_pass(in.set->cluster_of, tris, plan_.groups)) {
        if (renumber)
          pass_lists_.push_back(append_vertex_block(in.mesh, ids, optimize, order));
        else
          pass_triangles_.push_back(ids);
      }
    }
    if (zero_copies) zero_copy_lists_ = zero_copy_lists(in, optimize, order);
    mesh_ = std::make_unique<GpuMesh>(in.mesh, std::move(order), optimize);
    gpu_set_ = reordered_set(*in.set);
    pass_of_vertex_.assign(mesh_->vertex_count(), 0);
    if (!plan_.groups.pass_of.empty())
      for (std::size_t i = 0; i < pass_of_vertex_.size(); ++i)
        pass_of_vertex_[i] = plan_.groups.pass_of[in.set->cluster_of[mesh_->old_of_new()[i]]];
  }
  ~ClusterPath() override { glDeleteBuffers(1, &constant_buffer_); }

  void update(const Eigen::MatrixXd& lit, const Camera&) override {
    if (gpu_constants_) {
      gpu_constants_->compute(lit, constant_buffer_);
      return;
    }
    constants_.compute(lit, plan_.slot_of, host_.data());
    glBindBuffer(constant_target_, constant_buffer_);
    glBufferSubData(constant_target_, 0, GLsizeiptr(host_.size() * 4), host_.data());
  }

 protected:
  // The per-vertex attributes, the index ranges (whole mesh, then `pass_lists`), and the
  // constant buffer bound as `target`, written each frame on the GPU or from the CPU
  // (in.options.constants, recorded in in.stats).
  void upload(const PathInput& in, const std::vector<std::uint32_t>& cluster_attribute,
              GLenum target, bool shaded_on_gpu) {
    whole_ = mesh_->add_all_triangles();
    for (const auto& list : pass_lists_) pass_ranges_.push_back(mesh_->add_indices(list));
    for (const auto& ids : pass_triangles_) pass_ranges_.push_back(mesh_->add_triangles(ids));
    for (const auto& list : zero_copy_lists_) pass_ranges_.push_back(mesh_->add_indices(list));
    mesh_->uint_attribute(kAttrCluster, cluster_attribute);
    mesh_->uint_attribute(kAttrPass, pass_of_vertex_);
    const int N = gpu_set_.component_count;
    const int vectors = (N + 3) / 4;
    if (shaded_on_gpu && kAttrWeights + vectors > kAttrRadiance)
      throw std::invalid_argument(std::to_string(N) + " PCs need " + std::to_string(vectors) +
                                  " weight attributes but the GL context offers " +
                                  std::to_string(kAttrRadiance - kAttrWeights) +
                                  " (at most 40 PCs); compress with fewer PCs");
    mesh_->weight_attributes(gpu_set_.weights, N, shaded_on_gpu);
    mesh_->upload_indices();
    constant_target_ = target;
    constant_buffer_ = make_buffer(target, GLsizeiptr(host_.size() * 4), nullptr, GL_DYNAMIC_DRAW);
    if (shaded_on_gpu && constants_on_gpu(in.options.constants))
      gpu_constants_ = std::make_unique<GpuConstants>(constants_, plan_.slot_of, host_.size());
    in.stats.constants = gpu_constants_ ? Constants::kGpu : Constants::kCpu;
  }

  // kAuto (RendererOptions::constants): a hardware GPU whose storage blocks hold the rows.
  bool constants_on_gpu(Constants wanted) const {
    if (wanted != Constants::kAuto) return wanted == Constants::kGpu;
    const GlInfo info = current_gl_info();
    return !info.software_rasterizer() &&
           GpuConstants::row_bytes(constants_) <= std::size_t(std::max(info.max_ssbo_size, 0LL));
  }

  // Each vertex's slot (what the single-pass, decoupled and CPU shaders index by).
  std::vector<std::uint32_t> slots() const { return gpu_set_.cluster_of; }

  GLsizeiptr cluster_bytes() const { return GLsizeiptr(layout_.registers_per_cluster()) * 16; }

  // One cluster's vertices (contiguous, as vertices are sorted by slot) and the byte offset
  // of its constants.
  struct ClusterRange {
    GLint first = 0;
    GLsizei count = 0;
    GLintptr offset = 0;
  };
  // The clusters' ranges over GPU vertices [0, vertices), in slot order.
  std::vector<ClusterRange> cluster_ranges(std::size_t vertices) const {
    std::vector<std::uint32_t> slot_order(plan_.slot_of);
    std::sort(slot_order.begin(), slot_order.end());
    std::vector<ClusterRange> ranges;
    std::size_t v = 0;
    for (std::uint32_t slot : slot_order) {
      const std::size_t first = v;
      while (v < vertices && gpu_set_.cluster_of[v] == slot) ++v;
      if (v > first)
        ranges.push_back({GLint(first), GLsizei(v - first), GLintptr(slot) * cluster_bytes()});
    }
    PRTR_DCHECK(v == vertices);  // every vertex in exactly one cluster range
    return ranges;
  }

  // Each range's vertices once, as points with only its cluster's constants bound, so
  // `program` (ConstantAccess::kUniformFixed) indexes them by literals; transform feedback
  // writes the radiance at the vertices' own indices (the ranges follow each other from 0).
  void shade_by_feedback(GlProgram& program, const Camera& camera,
                         const std::vector<ClusterRange>& ranges, std::size_t vertices) {
    set_camera_uniforms(program, camera);
    begin_radiance_feedback(*mesh_);
    begin_work("feedback", vertices);
    for (const ClusterRange& r : ranges) {
      glBindBufferRange(GL_UNIFORM_BUFFER, kConstantsBinding, constant_buffer_, r.offset,
                        cluster_bytes());
      glDrawArrays(GL_POINTS, r.first, r.count);
    }
    end_work();
    end_radiance_feedback();
  }

  ShadingConstants constants_;
  ConstantLayout layout_;
  SlotPlan plan_;
  cpca::CompressedSet gpu_set_;  // in GPU vertex order; cluster_of holds slots, not ids
  std::vector<float> host_;
  std::vector<std::uint32_t> pass_of_vertex_;
  std::vector<std::vector<std::uint32_t>> pass_lists_;       // GPU indices, one per pass
  std::vector<std::vector<std::uint32_t>> pass_triangles_;   // without renumbering
  std::vector<std::vector<std::uint32_t>> zero_copy_lists_;  // GPU indices, one per pass
  std::vector<IndexRange> pass_ranges_;
  GLuint constant_buffer_ = 0;
  GLenum constant_target_ = GL_UNIFORM_BUFFER;
  std::unique_ptr<GpuConstants> gpu_constants_;  // null: computed on the CPU and uploaded

 private:
  // Per pass, its triangles' corners in GPU numbering: an own corner is its mesh vertex (GPU
  // index = position in `order`, the first vertex_count entries), a foreign one the vertex's
  // zero copy, appended to `order` on first need.
  std::vector<std::vector<std::uint32_t>> zero_copy_lists(const PathInput& in, bool optimize,
                                                          std::vector<std::uint32_t>& order) const {
    const std::size_t V = in.mesh.vertex_count();
    std::vector<std::uint32_t> gpu_of(V), zero_of(V, ~0u);
    for (std::size_t i = 0; i < V; ++i) gpu_of[order[i]] = std::uint32_t(i);
    std::vector<cpca::TriangleIndices> tris(in.mesh.triangles.begin(), in.mesh.triangles.end());
    std::vector<std::vector<std::uint32_t>> lists;
    for (const auto& ids : cpca::triangles_per_pass(in.set->cluster_of, tris, plan_.groups)) {
      const std::uint32_t p = std::uint32_t(lists.size());
      std::vector<std::uint32_t> list = triangle_corners(in.mesh, ids, optimize);
      for (std::uint32_t& v : list) {
        if (plan_.groups.pass_of[in.set->cluster_of[v]] == p) {
          v = gpu_of[v];
          continue;
        }
        if (zero_of[v] == ~0u) {
          zero_of[v] = std::uint32_t(order.size());
          order.push_back(v);
        }
        v = zero_of[v];
      }
      lists.push_back(std::move(list));
    }
    return lists;
  }

  std::vector<std::uint32_t> vertex_order(const meshes::Mesh& mesh, const cpca::CompressedSet& set,
                                          bool sort, bool optimize, bool renumber) const {
    std::vector<std::uint32_t> rank(set.vertex_count);
    if (renumber)
      rank = first_use_rank(mesh, optimize);
    else
      std::iota(rank.begin(), rank.end(), 0u);
    std::vector<std::uint32_t> order(set.vertex_count);
    std::iota(order.begin(), order.end(), 0u);
    auto key = [&](std::uint32_t v) {
      return std::pair(sort ? plan_.slot_of[set.cluster_of[v]] : 0u, rank[v]);
    };
    std::sort(order.begin(), order.end(),
              [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
    return order;
  }

  cpca::CompressedSet reordered_set(const cpca::CompressedSet& set) const {
    const std::size_t V = mesh_->vertex_count();
    const int N = set.component_count;
    cpca::CompressedSet out;
    out.component_count = N;
    out.cluster_of.resize(V);
    out.weights.resize(V * std::size_t(N));
    for (std::size_t i = 0; i < V; ++i) {
      const std::uint32_t o = mesh_->old_of_new()[i];
      out.cluster_of[i] = plan_.slot_of[set.cluster_of[o]];
      std::copy_n(set.weights.data() + o * std::size_t(N), N,
                  out.weights.data() + i * std::size_t(N));
    }
    return out;
  }
};

// Depth pre-pass, then one additive pass per super-cluster with GL_EQUAL depth, each drawing
// only its own triangles with only its clusters' constants in use. With multipass_feedback,
// each pass's shading is split in two: its own vertices are shaded once as points into the
// radiance buffer by transform feedback, cluster by cluster (a contiguous range each, as
// vertices are sorted by slot) with that cluster's part of the pass's constants bound, so
// every register index is a literal; then its triangles are drawn pass-through, other
// passes' corners reading a zero copy. llvmpipe's vertex stage masks a branch rather than
// skipping it, so in-draw shading paid the whole reconstruction for every foreign corner; a
// triangle draw's vertex stage cost ~2.6x a points draw's per vertex; and a per-vertex
// register index ~3x a literal one in a points draw (docs/ARCHITECTURE.md "Rendering").
class MultipassPath : public ClusterPath {
 public:
  explicit MultipassPath(const PathInput& in)
      : ClusterPath(in, true, in.options.multipass_feedback, in.options.multipass_feedback,
                    !in.options.multipass_feedback, true, in.options.multipass_feedback),
        feedback_(in.options.multipass_feedback) {
    std::vector<cpca::TriangleIndices> tris(in.mesh.triangles.begin(), in.mesh.triangles.end());
    const cpca::OverdrawStats od = cpca::overdraw(in.set->cluster_of, tris, plan_.groups);
    in.stats.triangles_per_pass = od.triangles_per_pass;
    in.stats.average_overdraw = od.average_overdraw;
    in.stats.passes = int(plan_.groups.passes.size());
    // Within a pass the in-draw shader indexes by the slot relative to the pass's range.
    std::vector<std::uint32_t> relative = slots();
    for (std::size_t i = 0; i < relative.size(); ++i)
      relative[i] -= std::uint32_t(plan_.pass_offset[pass_of_vertex_[i]] / cluster_bytes());
    upload(in, relative, GL_UNIFORM_BUFFER, true);
    depth_program_ =
        GlProgram("depth pre-pass", position_vertex_shader(), coverage_fragment_shader());
    if (feedback_)
      shade_program_ =
          GlProgram("multipass shading",
                    compressed_vertex_shader(layout_, ConstantAccess::kUniformFixed, 1, false),
                    radiance_fragment_shader(), true);
    else
      shade_program_ = GlProgram("multipass in-draw shading",
                                 compressed_vertex_shader(layout_, ConstantAccess::kUniformSlot,
                                                          plan_.slots_per_pass, true),
                                 radiance_fragment_shader(), true);
    if (feedback_) prepare_feedback();
  }

  std::size_t passes() const override { return pass_ranges_.size(); }
  bool pass_drew(std::size_t p) const override { return pass_ranges_[p].count > 0; }

  void draw_depth(const Camera& camera) override {
    set_camera_uniforms(depth_program_, camera);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);  // rgb = 0, alpha = coverage
    glDepthFunc(GL_LESS);
    begin_work("depth", whole_.referenced);
    mesh_->draw(whole_);
    end_work();
  }

  void draw(const Camera& camera, const std::vector<GLuint>& queries) override {
    if (feedback_) shade_own_vertices(camera);
    set_camera_uniforms(feedback_ ? passthrough_program_ : shade_program_, camera);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_FALSE);
    glDepthFunc(GL_EQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    if (feedback_ && queries.empty() && !work_ && !pass_ranges_.empty()) {
      // Pass-through needs no per-pass state and the passes' index lists follow each other,
      // so one draw blends the same triangles in the same order as one draw per pass.
      IndexRange all = pass_ranges_.front();
      all.count = GLsizei(pass_ranges_.back().first + pass_ranges_.back().count - all.first);
      mesh_->draw(all);
      glDisable(GL_BLEND);
      return;
    }
    for (std::size_t p = 0; p < pass_ranges_.size(); ++p) {
      if (pass_ranges_[p].count == 0) continue;
      if (!feedback_) bind_pass(p);
      if (!queries.empty()) glBeginQuery(GL_PRIMITIVES_GENERATED, queries[p]);
      begin_work("shade " + std::to_string(p), pass_ranges_[p].referenced);
      mesh_->draw(pass_ranges_[p]);
      end_work();
      if (!queries.empty()) glEndQuery(GL_PRIMITIVES_GENERATED);
    }
    glDisable(GL_BLEND);
  }

  // In-draw shading: vertices outside a pass output zero, so the passes' captures sum to the
  // radiance. Feedback: the radiance buffer's mesh vertices (not the zero copies).
  std::vector<Rgb> capture(const Camera& camera) override {
    if (feedback_) {
      shade_own_vertices(camera);
      std::vector<Rgb> radiance;
      mesh_->read(mesh_->radiance_buffer(), radiance, false);
      radiance.resize(mesh_->source_vertex_count());
      return radiance;
    }
    set_camera_uniforms(shade_program_, camera);
    std::vector<Rgb> radiance(mesh_->vertex_count(), Rgb::Zero());
    for (std::size_t p = 0; p < plan_.pass_offset.size(); ++p) {
      bind_pass(p);
      mesh_->capture_points(radiance, true);
    }
    return radiance;
  }

 private:
  void bind_pass(std::size_t p) {
    if (!feedback_) glUniform1ui(shade_program_.uniform("u_pass"), GLuint(p));
    glBindBufferRange(GL_UNIFORM_BUFFER, kConstantsBinding, constant_buffer_, plan_.pass_offset[p],
                      GLsizeiptr(plan_.slots_per_pass) * cluster_bytes());
  }

  // The clusters' ranges over the mesh vertices, in pass order (slots are assigned pass by
  // pass), and zeros in the radiance buffer, which feedback never writes past the mesh
  // vertices: the zero copies' radiance.
  void prepare_feedback() {
    own_ranges_ = cluster_ranges(mesh_->source_vertex_count());
    const std::vector<float> zeros(mesh_->vertex_count() * 3, 0.f);
    glBindBuffer(GL_ARRAY_BUFFER, mesh_->radiance_buffer());
    glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(zeros.size() * 4), zeros.data());
    passthrough_program_ =
        GlProgram("pass-through", passthrough_vertex_shader(), radiance_fragment_shader(), true);
  }

  void shade_own_vertices(const Camera& camera) {
    shade_by_feedback(shade_program_, camera, own_ranges_, mesh_->source_vertex_count());
  }

  bool feedback_;
  std::vector<ClusterRange> own_ranges_;
  GlProgram depth_program_, shade_program_, passthrough_program_;
};

// All clusters' constants in one SSBO indexed by the vertex's slot; one draw.
class SinglepassPath : public ClusterPath {
 public:
  explicit SinglepassPath(const PathInput& in) : ClusterPath(in, false, false, false, false, true) {
    upload(in, slots(), GL_SHADER_STORAGE_BUFFER, true);
    program_ = GlProgram("single-pass shading",
                         compressed_vertex_shader(layout_, ConstantAccess::kStorage, 0, false),
                         radiance_fragment_shader(), true);
    shade_whole(&program_, kConstantsBinding, constant_buffer_);
  }

 private:
  GlProgram program_;
};

// Each cluster's vertices (one contiguous range, as vertices are sorted by slot) shaded once
// as points with only its constants bound, so every register index is a literal; transform
// feedback writes the radiance in place; then one pass-through draw of all triangles.
class DecoupledPath : public ClusterPath {
 public:
  explicit DecoupledPath(const PathInput& in) : ClusterPath(in, true, true, true, false, true) {
    upload(in, slots(), GL_UNIFORM_BUFFER, true);
    ranges_ = cluster_ranges(mesh_->vertex_count());
    shade_program_ =
        GlProgram("decoupled shading",
                  compressed_vertex_shader(layout_, ConstantAccess::kUniformFixed, 1, false),
                  radiance_fragment_shader(), true);
    passthrough_program_ =
        GlProgram("pass-through", passthrough_vertex_shader(), radiance_fragment_shader(), true);
  }
  void draw(const Camera& camera, const std::vector<GLuint>& queries) override {
    shade_by_feedback(shade_program_, camera, ranges_, mesh_->vertex_count());
    draw_whole(passthrough_program_, camera, queries);
  }
  std::vector<Rgb> capture(const Camera& camera) override {
    shade_by_feedback(shade_program_, camera, ranges_, mesh_->vertex_count());
    std::vector<Rgb> radiance;
    mesh_->read(mesh_->radiance_buffer(), radiance, false);
    return radiance;
  }

 private:
  std::vector<ClusterRange> ranges_;
  GlProgram shade_program_, passthrough_program_;
};

// The same constants, per-vertex radiance in C++ (render/shading.h), drawn pass-through.
class CpuPath : public ClusterPath {
 public:
  explicit CpuPath(const PathInput& in) : ClusterPath(in, false, false, false, false, false) {
    upload(in, slots(), GL_UNIFORM_BUFFER, false);
    program_ =
        GlProgram("pass-through", passthrough_vertex_shader(), radiance_fragment_shader(), true);
  }
  void update(const Eigen::MatrixXd& lit, const Camera& camera) override {
    constants_.compute(lit, plan_.slot_of, host_.data());
    shade_vertices(gpu_set_, layout_, host_.data(), mesh_->mesh(), camera.eye, radiance_);
    glBindBuffer(GL_ARRAY_BUFFER, mesh_->radiance_buffer());
    glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(radiance_.size() * 12), radiance_.data());
  }
  void draw(const Camera& camera, const std::vector<GLuint>& queries) override {
    draw_whole(program_, camera, queries);
  }
  std::vector<Rgb> capture(const Camera&) override { return radiance_; }

 private:
  GlProgram program_;
  std::vector<Rgb> radiance_;
};

}  // namespace

std::unique_ptr<RenderPath> make_cluster_path(const PathInput& in) {
  if (!in.set)
    throw std::invalid_argument("mode " + std::string(kModeNames.name(in.options.mode)) +
                                " needs a compressed set");
  cpca::validate(*in.set);
  if (in.set->vertex_count != in.mesh.vertex_count())
    throw std::invalid_argument("the compressed set has " + std::to_string(in.set->vertex_count) +
                                " vertices but the mesh has " +
                                std::to_string(in.mesh.vertex_count()) +
                                "; use the mesh it was baked from");
  switch (in.options.mode) {
    case Mode::kMultipass:
      return std::make_unique<MultipassPath>(in);
    case Mode::kSinglepass:
      return std::make_unique<SinglepassPath>(in);
    case Mode::kDecoupled:
      return std::make_unique<DecoupledPath>(in);
    case Mode::kCpu:
      return std::make_unique<CpuPath>(in);
    case Mode::kUncompressed:
      break;
  }
  throw std::invalid_argument("mode " + std::string(kModeNames.name(in.options.mode)) +
                              " is not a cluster path");
}

}  // namespace render
