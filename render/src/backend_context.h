// render/src/backend_context.h (private): what GlContext needs of a backend (OSMesa or EGL).
// Each backend resolves the GL entry points through its own GetProcAddress into one table
// (gl_api.h) and makes that table current with its context.
#pragma once

#include <memory>
#include <string>

namespace render {

class BackendContext {
 public:
  virtual ~BackendContext() = default;
  // Makes the context current on this thread and points gl::current at its entry points.
  virtual void make_current() = 0;
  // One line for logs and gl-info: backend and device.
  virtual std::string describe() const = 0;
};

// An OSMesa core context of at least major.minor with a width x height RGBA8 default buffer.
std::unique_ptr<BackendContext> make_osmesa_context(int major, int minor, int width, int height);

// An EGL core context of at least major.minor on EGL device `device` (-1: the first hardware
// device, else the first), with no surface: the renderer draws into framebuffer objects.
std::unique_ptr<BackendContext> make_egl_context(int device, int major, int minor);

}  // namespace render
