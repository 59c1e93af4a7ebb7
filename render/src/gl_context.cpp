#include "render/gl_context.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace render {

struct GlContext::Impl {
  OSMesaContext context = nullptr;
  std::vector<unsigned char> buffer;
  int width = 0, height = 0;
};

GlContext::GlContext(int major, int minor, int width, int height)
    : impl_(std::make_unique<Impl>()) {
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         24,
                         OSMESA_STENCIL_BITS,
                         0,
                         OSMESA_ACCUM_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         major,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         minor,
                         0};
  impl_->context = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!impl_->context) {
    throw GlError("OSMesa could not create an OpenGL " + std::to_string(major) + "." +
                  std::to_string(minor) +
                  " core context (is Mesa's llvmpipe installed? try LIBGL_ALWAYS_SOFTWARE=1 or "
                  "a newer libosmesa6)");
  }
  impl_->width = width;
  impl_->height = height;
  impl_->buffer.assign(std::size_t(width) * height * 4, 0);
  make_current();
}

GlContext::~GlContext() {
  if (impl_ && impl_->context) OSMesaDestroyContext(impl_->context);
}

void GlContext::make_current() {
  if (!OSMesaMakeCurrent(impl_->context, impl_->buffer.data(), GL_UNSIGNED_BYTE, impl_->width,
                         impl_->height)) {
    throw GlError("OSMesaMakeCurrent failed");
  }
}

int GlInfo::default_register_budget() const {
  return std::min(max_vertex_uniform_vectors, max_uniform_block_size / 16);
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
