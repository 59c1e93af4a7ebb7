// render/src/work_counter.h (private): GL_ARB_pipeline_statistics_query around each draw of a
// frame, so the cost of a path is counted (vertex-shader invocations, primitives, fragment
// invocations) rather than only timed: on a shared machine the counts are deterministic and
// the times are not (docs/ARCHITECTURE.md "Rendering", Measured).
#pragma once

#include "gl_program.h"
#include "render/renderer.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace render {

class WorkCounter {
 public:
  WorkCounter() = default;
  ~WorkCounter();
  WorkCounter(const WorkCounter&) = delete;
  WorkCounter& operator=(const WorkCounter&) = delete;

  // Starts a frame: forgets the previous frame's passes, keeps the query objects.
  void reset();
  // Brackets one draw; `referenced` is how many distinct vertices it can reach (the lower
  // bound of its vertex-shader invocations).
  void begin(std::string label, std::uint64_t referenced);
  void end();
  // The counts of the passes since reset() (waits for them).
  std::vector<PassWork> read() const;

 private:
  static constexpr std::array<GLenum, 3> kTargets = {
      GL_VERTEX_SHADER_INVOCATIONS, GL_PRIMITIVES_SUBMITTED, GL_FRAGMENT_SHADER_INVOCATIONS};
  std::vector<std::array<GLuint, 3>> queries_;
  std::vector<PassWork> passes_;
};

}  // namespace render
