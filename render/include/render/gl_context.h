// render/gl_context.h: an offscreen OpenGL context through OSMesa (Mesa's llvmpipe on the
// CPU; no display, no GPU). The OSMesa and GL headers stay inside render/src.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace render {

struct GlInfo {
  std::string version;       // GL_VERSION
  std::string renderer;      // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string glsl_version;  // GL_SHADING_LANGUAGE_VERSION
  int major = 0, minor = 0;
  bool core_profile = false;
  int max_vertex_uniform_vectors = 0;  // vec4 count
  int max_uniform_block_size = 0;      // bytes
  long long max_ssbo_size = 0;         // bytes

  // The vec4 registers one pass may bind when no budget is given: a pass's constants are one
  // UBO range, which must fit both the vertex stage's uniform vectors and one uniform block.
  // Every default budget (renderer, pass grouping, benchmark) comes from here, so a driver
  // whose block is the smaller limit cannot make them disagree.
  int default_register_budget() const;
};

// The limits of the context current on this thread (GlContext::info of it).
GlInfo current_gl_info();

class GlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Owns the context and makes it current on the constructing thread. The default OSMesa
// buffer is `width` x `height` RGBA8; the renderer draws into its own framebuffer objects.
class GlContext {
 public:
  // Requests a core profile of at least major.minor; throws GlError with OSMesa's answer
  // when Mesa cannot provide it.
  explicit GlContext(int major = 4, int minor = 5, int width = 16, int height = 16);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  void make_current();
  GlInfo info() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// While alive, collects the current context's KHR_debug messages of type error or undefined
// behaviour (synchronous output, so each message follows the call that caused it). Tests
// hold the renderer to an empty log: llvmpipe tolerates hazards a stricter driver rejects.
class GlDebugLog {
 public:
  GlDebugLog();
  ~GlDebugLog();
  GlDebugLog(const GlDebugLog&) = delete;
  GlDebugLog& operator=(const GlDebugLog&) = delete;
  const std::vector<std::string>& messages() const { return messages_; }
  void add(std::string message) { messages_.push_back(std::move(message)); }

 private:
  std::vector<std::string> messages_;
};

// Throws GlError naming `where` and the GL error code(s) when glGetError reports any.
void check_gl(const char* where);

}  // namespace render
