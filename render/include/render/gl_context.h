// render/gl_context.h: an offscreen OpenGL context, no window and no display server, from
// one of two backends chosen at run time: OSMesa (Mesa's llvmpipe on the CPU; the default,
// it runs anywhere) or EGL on an EGL device (a GPU's driver, or Mesa's software device). The
// OSMesa, EGL and GL headers stay inside render/src; nothing else knows which backend runs.
#pragma once

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace render {

enum class GlBackend { kOsmesa, kEgl };

// "osmesa" or "egl"; parse_gl_backend is its inverse (nullopt for any other text).
const char* gl_backend_name(GlBackend backend);
std::optional<GlBackend> parse_gl_backend(std::string_view name);

// Which backend and, for EGL, which device (-1: the first hardware device, else the first).
struct GlSelection {
  GlBackend backend = GlBackend::kOsmesa;
  int device = -1;
};

// PRTR_GL (osmesa|egl) and PRTR_GL_DEVICE (an index) from the environment, OSMesa when
// unset; throws GlError naming the variable when a value is not one of those.
GlSelection gl_selection_from_environment();

// One EGL device as EGL describes it (prtr gl-info lists them).
struct EglDevice {
  int index = 0;
  bool software = false;  // EGL_MESA_device_software: llvmpipe, not a GPU
  std::string drm_file;   // e.g. /dev/dri/card0, where EGL_EXT_device_drm says
  std::string vendor;     // EGL_VENDOR of its display
  std::string extensions;
};

// Throws GlError when libEGL cannot be loaded or offers no device enumeration.
std::vector<EglDevice> list_egl_devices();

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
  // UBO range, so one uniform block's size bounds them. GL_MAX_VERTEX_UNIFORM_VECTORS counts
  // the default block only (uniform blocks fall under the combined limit, which adds every
  // block's size): llvmpipe offers 4096 of each, but NVIDIA 1024 default-block vectors and a
  // 64 KiB block, and taking the smaller held a GPU to 4 of the thesis's clusters a pass
  // instead of 16. Every default budget (renderer, pass grouping, benchmark) comes from here,
  // so they cannot disagree.
  int default_register_budget() const;
  // Mesa's llvmpipe or softpipe: the CPU rasterises, so what is cheap on a GPU (half-float
  // blending, compute dispatches) may not be here.
  bool software_rasterizer() const;
};

// The limits of the context current on this thread (GlContext::info of it).
GlInfo current_gl_info();

class GlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Owns the context and makes it current on the constructing thread. The renderer draws into
// its own framebuffer objects: an OSMesa context also has a `width` x `height` RGBA8 default
// buffer, an EGL one has none (surfaceless).
class GlContext {
 public:
  // Requests a core profile of at least major.minor from the backend the environment names
  // (gl_selection_from_environment; OSMesa when unset); throws GlError with the backend's
  // answer when it cannot provide one. A failed EGL start says how to use OSMesa instead.
  explicit GlContext(int major = 4, int minor = 5, int width = 16, int height = 16);
  explicit GlContext(const GlSelection& selection, int major = 4, int minor = 5, int width = 16,
                     int height = 16);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  void make_current();
  GlInfo info() const;
  GlBackend backend() const;
  // The backend and device in words, e.g. "egl device 0 (NVIDIA)".
  std::string description() const;

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
