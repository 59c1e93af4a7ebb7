#include "work_counter.h"

#include "common/check.h"

#include <utility>

namespace render {

WorkCounter::~WorkCounter() {
  for (auto& q : queries_) glDeleteQueries(GLsizei(q.size()), q.data());
}

void WorkCounter::reset() {
  passes_.clear();
}

void WorkCounter::begin(std::string label, std::uint64_t referenced) {
  if (queries_.size() <= passes_.size()) {
    std::array<GLuint, 3> q{};
    glGenQueries(GLsizei(q.size()), q.data());
    queries_.push_back(q);
  }
  PassWork pass;
  pass.label = std::move(label);
  pass.referenced_vertices = referenced;
  passes_.push_back(std::move(pass));
  const auto& q = queries_[passes_.size() - 1];
  for (std::size_t i = 0; i < kTargets.size(); ++i) glBeginQuery(kTargets[i], q[i]);
}

void WorkCounter::end() {
  PRTR_DCHECK(!passes_.empty());
  for (GLenum target : kTargets) glEndQuery(target);
}

std::vector<PassWork> WorkCounter::read() const {
  std::vector<PassWork> out = passes_;
  for (std::size_t p = 0; p < out.size(); ++p) {
    GLuint v[3] = {0, 0, 0};  // libOSMesa exports the 32-bit query getter only
    for (std::size_t i = 0; i < 3; ++i) glGetQueryObjectuiv(queries_[p][i], GL_QUERY_RESULT, &v[i]);
    out[p].vs_invocations = v[0];
    out[p].primitives = v[1];
    out[p].fs_invocations = v[2];
  }
  return out;
}

WorkTotals work_totals(const std::vector<PassWork>& passes) {
  WorkTotals t;
  for (const PassWork& p : passes) {
    t.vs_invocations += p.vs_invocations;
    t.primitives += p.primitives;
    t.fs_invocations += p.fs_invocations;
    t.referenced_vertices += p.referenced_vertices;
  }
  t.vs_per_referenced_vertex =
      t.referenced_vertices ? double(t.vs_invocations) / double(t.referenced_vertices) : 0.0;
  return t;
}

}  // namespace render
