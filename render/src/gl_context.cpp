#include "render/gl_context.h"

#include "backend_context.h"
#include "gl_api.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace render {

const char* gl_backend_name(GlBackend backend) {
  return backend == GlBackend::kEgl ? "egl" : "osmesa";
}

std::optional<GlBackend> parse_gl_backend(std::string_view name) {
  if (name == "osmesa") return GlBackend::kOsmesa;
  if (name == "egl") return GlBackend::kEgl;
  return std::nullopt;
}

GlSelection gl_selection_from_environment() {
  GlSelection s;
  if (const char* gl = std::getenv("PRTR_GL"); gl && *gl) {
    const auto backend = parse_gl_backend(gl);
    if (!backend)
      throw GlError(std::string("PRTR_GL=") + gl + " is not a GL backend: use osmesa or egl");
    s.backend = *backend;
  }
  if (const char* dev = std::getenv("PRTR_GL_DEVICE"); dev && *dev) {
    char* end = nullptr;
    errno = 0;
    const long n = std::strtol(dev, &end, 10);
    if (*end || errno || n < 0 || n > 1000)
      throw GlError(std::string("PRTR_GL_DEVICE=") + dev + " is not an EGL device index");
    s.device = int(n);
  }
  return s;
}

struct GlContext::Impl {
  GlBackend backend = GlBackend::kOsmesa;
  std::unique_ptr<BackendContext> context;
};

GlContext::GlContext(int major, int minor, int width, int height)
    : GlContext(gl_selection_from_environment(), major, minor, width, height) {}

GlContext::GlContext(const GlSelection& selection, int major, int minor, int width, int height)
    : impl_(std::make_unique<Impl>()) {
  impl_->backend = selection.backend;
  if (selection.backend == GlBackend::kOsmesa) {
    impl_->context = make_osmesa_context(major, minor, width, height);
    return;
  }
  try {
    impl_->context = make_egl_context(selection.device, major, minor);
  } catch (const GlError& e) {
    throw GlError(std::string("EGL failed: ") + e.what() +
                  "; render on the CPU with OSMesa instead (--gl osmesa, or PRTR_GL=osmesa)");
  }
}

GlContext::~GlContext() = default;

void GlContext::make_current() {
  impl_->context->make_current();
}

GlBackend GlContext::backend() const {
  return impl_->backend;
}

std::string GlContext::description() const {
  return impl_->context->describe();
}

int GlInfo::default_register_budget() const {
  return max_uniform_block_size / 16;
}

bool GlInfo::software_rasterizer() const {
  return renderer.find("llvmpipe") != std::string::npos ||
         renderer.find("softpipe") != std::string::npos;
}

GlInfo GlContext::info() const {
  return current_gl_info();
}

GlInfo current_gl_info() {
  auto str = [](GLenum name) {
    const auto* s = reinterpret_cast<const char*>(glGetString(name));
    return std::string(s ? s : "");
  };
  GlInfo i;
  i.version = str(GL_VERSION);
  i.renderer = str(GL_RENDERER);
  i.glsl_version = str(GL_SHADING_LANGUAGE_VERSION);
  glGetIntegerv(GL_MAJOR_VERSION, &i.major);
  glGetIntegerv(GL_MINOR_VERSION, &i.minor);
  GLint mask = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
  i.core_profile = (mask & GL_CONTEXT_CORE_PROFILE_BIT) != 0;
  glGetIntegerv(GL_MAX_VERTEX_UNIFORM_VECTORS, &i.max_vertex_uniform_vectors);
  glGetIntegerv(GL_MAX_UNIFORM_BLOCK_SIZE, &i.max_uniform_block_size);
  GLint64 ssbo = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &ssbo);
  i.max_ssbo_size = ssbo;
  check_gl("GlContext::info");
  return i;
}

namespace {

void GLAPIENTRY on_debug_message(GLenum, GLenum type, GLuint, GLenum, GLsizei length,
                                 const GLchar* message, const void* user) {
  if (type != GL_DEBUG_TYPE_ERROR && type != GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR) return;
  auto* log = static_cast<GlDebugLog*>(const_cast<void*>(user));
  log->add(length < 0 ? std::string(message) : std::string(message, std::size_t(length)));
}

}  // namespace

GlDebugLog::GlDebugLog() {
  glEnable(GL_DEBUG_OUTPUT);
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(on_debug_message, this);
  glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
}

GlDebugLog::~GlDebugLog() {
  glDebugMessageCallback(nullptr, nullptr);
  glDisable(GL_DEBUG_OUTPUT);
}

void check_gl(const char* where) {
  std::string codes;
  for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", e);
    codes += codes.empty() ? buf : std::string(", ") + buf;
    if (codes.size() > 64) break;  // a lost context can report forever
  }
  if (!codes.empty()) throw GlError(std::string("OpenGL error at ") + where + ": " + codes);
}

}  // namespace render
