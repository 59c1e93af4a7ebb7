#include "gpu_constants.h"

#include "gpu_mesh.h"
#include "render/gl_context.h"

#include <algorithm>
#include <limits>
#include <string>

namespace render {

namespace {

// Storage bindings of the dispatch only; the paths bind theirs (0 and 1) at draw time.
constexpr GLuint kRowsBinding = 4, kSourcesBinding = 5, kLightingBinding = 6, kOutputBinding = 7;
constexpr std::uint32_t kNoSource = 0xffffffffu;
constexpr GLuint kGroupSize = 64;

// One invocation per constant float: the dot product of one transfer row with one colour of
// the lighting. `sources` names the row (high bits) and the colour (low 2 bits), or none for
// the padding between clusters, which stays zero.
const char* kComputeShader = R"(#version 450 core
layout(local_size_x = 64) in;
layout(std430, binding = 4) readonly buffer Rows { float rows[]; };
layout(std430, binding = 5) readonly buffer Sources { uint sources[]; };
layout(std430, binding = 6) readonly buffer Lighting { float lighting[]; };
layout(std430, binding = 7) writeonly buffer Constants { float constants[]; };
uniform uint u_n;
uniform uint u_count;
void main() {
  uint o = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u + gl_GlobalInvocationID.x;
  if (o >= u_count) return;
  uint source = sources[o];
  float sum = 0.0;
  if (source != 0xffffffffu) {
    uint base = (source >> 2) * u_n;
    uint light = (source & 3u) * u_n;
    for (uint j = 0u; j < u_n; ++j) sum += rows[base + j] * lighting[light + j];
  }
  constants[o] = sum;
}
)";

}  // namespace

std::size_t GpuConstants::row_bytes(const ShadingConstants& constants) {
  std::size_t floats = 0;
  for (int k = 0; k < constants.cluster_count(); ++k)
    floats += std::size_t(constants.rows(k).size());
  return floats * sizeof(float);
}

GpuConstants::GpuConstants(const ShadingConstants& constants,
                           const std::vector<std::uint32_t>& slot_of, std::size_t total_floats)
    : program_("frame constants", kComputeShader), n_(constants.coefficient_count()) {
  const std::size_t bytes = row_bytes(constants);
  const auto limit = std::size_t(std::max(current_gl_info().max_ssbo_size, 0LL));
  if (bytes > limit)
    throw GlError("the clusters' transfer rows take " + std::to_string(bytes >> 20) +
                  " MiB but a shader storage block holds " + std::to_string(limit >> 20) +
                  " MiB in this GL context; use --constants cpu");
  if (total_floats > std::numeric_limits<std::uint32_t>::max())
    throw GlError("the constant buffer is too large for GPU constants; use --constants cpu");
  const ConstantLayout& lay = constants.layout();
  std::vector<float> rows;
  rows.reserve(bytes / sizeof(float));
  std::vector<std::uint32_t> sources(total_floats, kNoSource);
  for (int k = 0; k < constants.cluster_count(); ++k) {
    const auto& m = constants.rows(k);
    const std::size_t first_row = rows.size() / std::size_t(n_);
    rows.insert(rows.end(), m.data(), m.data() + m.size());
    const std::size_t base = std::size_t(slot_of[std::size_t(k)]) * lay.floats_stride();
    for (int t = 0; t < lay.terms; ++t)
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i < lay.rows; ++i) {
          const std::size_t row = first_row + std::size_t(constants.row(t, c, i));
          if (row >= (std::size_t(1) << 30))
            throw GlError("too many transfer rows for GPU constants; use --constants cpu");
          sources[base + std::size_t(lay.offset(t, c, i))] = std::uint32_t(row << 2 | c);
        }
  }
  rows_ = make_buffer(GL_SHADER_STORAGE_BUFFER, GLsizeiptr(bytes), rows.data(), GL_STATIC_DRAW);
  sources_ = make_buffer(GL_SHADER_STORAGE_BUFFER, GLsizeiptr(sources.size() * 4), sources.data(),
                         GL_STATIC_DRAW);
  host_lighting_.resize(std::size_t(3 * n_));
  lighting_ = make_buffer(GL_SHADER_STORAGE_BUFFER, GLsizeiptr(host_lighting_.size() * 4), nullptr,
                          GL_DYNAMIC_DRAW);
  count_ = std::uint32_t(total_floats);
  check_gl("GpuConstants: set-up");
}

GpuConstants::~GpuConstants() {
  const GLuint buffers[] = {rows_, sources_, lighting_};
  glDeleteBuffers(3, buffers);
}

void GpuConstants::compute(const Eigen::Ref<const Eigen::MatrixXd>& lighting, GLuint buffer) {
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < n_; ++j) host_lighting_[std::size_t(c * n_ + j)] = float(lighting(j, c));
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, lighting_);
  glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, GLsizeiptr(host_lighting_.size() * 4),
                  host_lighting_.data());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRowsBinding, rows_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kSourcesBinding, sources_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kLightingBinding, lighting_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kOutputBinding, buffer);
  program_.use();
  glUniform1ui(program_.uniform("u_n"), GLuint(n_));
  glUniform1ui(program_.uniform("u_count"), count_);
  // Past 65535 groups (GL's guaranteed limit in x) the rest go in y.
  const GLuint groups = (count_ + kGroupSize - 1) / kGroupSize;
  const GLuint x = std::min<GLuint>(groups, 65535);
  glDispatchCompute(x, (groups + x - 1) / x, 1);
  // The passes read the constants as a uniform block (multipass, decoupled) or as storage
  // (single pass).
  glMemoryBarrier(GL_UNIFORM_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kOutputBinding, 0);
}

}  // namespace render
