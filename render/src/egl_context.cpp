// The EGL backend: a context on an EGL device (EGL_EXT_platform_device) with no window, no
// display server and no surface; the renderer draws into framebuffer objects. The same code
// runs on an NVIDIA driver behind glvnd's libEGL and on Mesa's llvmpipe (its software device).
#include "backend_context.h"
#include "gl_api.h"
#include "render/gl_context.h"
#include "shared_library.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <cstring>
#include <mutex>

namespace render {
namespace {

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = std::strstr(list, name); p; p = std::strstr(p + n, name))
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

std::string hex(EGLint e) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", unsigned(e));
  return buf;
}

// libEGL's entry points (core and the device extensions) and the GL table resolved through
// eglGetProcAddress, once per process. glvnd answers context-independent dispatch stubs, so
// one table serves every EGL context and device.
struct EglApi {
  SharedLibrary lib{"libEGL.so.1", "libEGL.so"};
  PFNEGLGETPROCADDRESSPROC get_proc =
      reinterpret_cast<PFNEGLGETPROCADDRESSPROC>(lib.symbol("eglGetProcAddress"));

  template <class F>
  F resolve(const char* name) const {
    void* p = lib.symbol(name);  // core EGL: exported by every libEGL
    if (!p && get_proc) return reinterpret_cast<F>(get_proc(name));
    return reinterpret_cast<F>(p);
  }

  PFNEGLGETERRORPROC get_error = resolve<PFNEGLGETERRORPROC>("eglGetError");
  PFNEGLQUERYSTRINGPROC query_string = resolve<PFNEGLQUERYSTRINGPROC>("eglQueryString");
  PFNEGLINITIALIZEPROC initialize = resolve<PFNEGLINITIALIZEPROC>("eglInitialize");
  PFNEGLBINDAPIPROC bind_api = resolve<PFNEGLBINDAPIPROC>("eglBindAPI");
  PFNEGLCHOOSECONFIGPROC choose_config = resolve<PFNEGLCHOOSECONFIGPROC>("eglChooseConfig");
  PFNEGLCREATECONTEXTPROC create_context = resolve<PFNEGLCREATECONTEXTPROC>("eglCreateContext");
  PFNEGLDESTROYCONTEXTPROC destroy_context = resolve<PFNEGLDESTROYCONTEXTPROC>("eglDestroyContext");
  PFNEGLCREATEPBUFFERSURFACEPROC create_pbuffer =
      resolve<PFNEGLCREATEPBUFFERSURFACEPROC>("eglCreatePbufferSurface");
  PFNEGLDESTROYSURFACEPROC destroy_surface = resolve<PFNEGLDESTROYSURFACEPROC>("eglDestroySurface");
  PFNEGLMAKECURRENTPROC make_current = resolve<PFNEGLMAKECURRENTPROC>("eglMakeCurrent");
  PFNEGLGETCURRENTCONTEXTPROC get_current_context =
      resolve<PFNEGLGETCURRENTCONTEXTPROC>("eglGetCurrentContext");
  PFNEGLQUERYDEVICESEXTPROC query_devices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(get_proc("eglQueryDevicesEXT"));
  PFNEGLQUERYDEVICESTRINGEXTPROC query_device_string =
      reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(get_proc("eglQueryDeviceStringEXT"));
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(get_proc("eglGetPlatformDisplayEXT"));
  gl::Functions functions;
  std::once_flag functions_loaded;

  EglApi() {
    if (!get_proc || !get_error || !query_string || !initialize || !bind_api || !create_context ||
        !destroy_context || !make_current || !get_current_context)
      throw GlError(lib.name() + " lacks core EGL entry points");
    const char* client = query_string(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!query_devices || !query_device_string || !get_platform_display ||
        !has_extension(client, "EGL_EXT_platform_device"))
      throw GlError(lib.name() +
                    " offers no device platform (EGL_EXT_device_enumeration, "
                    "EGL_EXT_platform_device)");
  }

  std::vector<EGLDeviceEXT> devices() const {
    EGLint n = 0;
    if (!query_devices(0, nullptr, &n) || n <= 0) return {};
    std::vector<EGLDeviceEXT> d(std::size_t(n), nullptr);
    if (!query_devices(n, d.data(), &n)) return {};
    d.resize(std::size_t(n));
    return d;
  }

  // The device's display, initialised. EGL hands out one display per device and counts no
  // references, so displays are never terminated: a second context on the device shares it.
  EGLDisplay display(EGLDeviceEXT device, const std::string& what) const {
    EGLDisplay d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
    EGLint major = 0, minor = 0;
    if (d == EGL_NO_DISPLAY || !initialize(d, &major, &minor))
      throw GlError("EGL cannot initialise " + what + " (error " + hex(get_error()) + ")");
    return d;
  }
};

EglApi& egl_api() {
  static EglApi instance;  // throws on every call while libEGL cannot be used
  return instance;
}

bool is_software(const EglApi& egl, EGLDeviceEXT device) {
  return has_extension(egl.query_device_string(device, EGL_EXTENSIONS), "EGL_MESA_device_software");
}

class EglContext final : public BackendContext {
 public:
  EglContext(int device, int major, int minor) : api_(egl_api()) {
    const std::vector<EGLDeviceEXT> devices = api_.devices();
    if (devices.empty()) throw GlError("EGL lists no devices");
    if (device >= int(devices.size()))
      throw GlError("EGL device " + std::to_string(device) + " does not exist: there are " +
                    std::to_string(devices.size()) + " (0 to " +
                    std::to_string(devices.size() - 1) + ")");
    if (device < 0) {  // the first hardware device, else the first (Mesa's software one)
      device = 0;
      for (std::size_t i = 0; i < devices.size(); ++i)
        if (!is_software(api_, devices[i])) {
          device = int(i);
          break;
        }
    }
    device_ = device;
    const std::string what = "EGL device " + std::to_string(device);
    display_ = api_.display(devices[std::size_t(device)], what);
    vendor_ =
        api_.query_string(display_, EGL_VENDOR) ? api_.query_string(display_, EGL_VENDOR) : "";
    if (!api_.bind_api(EGL_OPENGL_API))
      throw GlError(what + " offers no desktop OpenGL (eglBindAPI)");
    const char* ext = api_.query_string(display_, EGL_EXTENSIONS);
    // Without EGL_KHR_no_config_context a context needs a config; one for pbuffers also
    // serves the 1 x 1 surface made below when the display cannot go surfaceless.
    EGLConfig config = EGL_NO_CONFIG_KHR;
    const bool surfaceless = has_extension(ext, "EGL_KHR_surfaceless_context");
    if (!has_extension(ext, "EGL_KHR_no_config_context") || !surfaceless) {
      const EGLint want[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT,
                             EGL_NONE};
      EGLint n = 0;
      if (!api_.choose_config || !api_.choose_config(display_, want, &config, 1, &n) || n < 1)
        throw GlError(what + " has no OpenGL config");
    }
    const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                              major,
                              EGL_CONTEXT_MINOR_VERSION,
                              minor,
                              EGL_CONTEXT_OPENGL_PROFILE_MASK,
                              EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                              EGL_NONE};
    context_ = api_.create_context(display_, config, EGL_NO_CONTEXT, attribs);
    if (context_ == EGL_NO_CONTEXT)
      throw GlError(what + " (" + vendor_ + ") cannot create an OpenGL " + std::to_string(major) +
                    "." + std::to_string(minor) + " core context (error " + hex(api_.get_error()) +
                    ")");
    if (!surfaceless) {
      const EGLint size[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
      surface_ = api_.create_pbuffer ? api_.create_pbuffer(display_, config, size) : EGL_NO_SURFACE;
      if (surface_ == EGL_NO_SURFACE) {
        api_.destroy_context(display_, context_);
        throw GlError(what + " is neither surfaceless nor offers a pbuffer");
      }
    }
    make_current();
  }

  ~EglContext() override {
    if (api_.get_current_context() == context_)
      api_.make_current(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (surface_ != EGL_NO_SURFACE) api_.destroy_surface(display_, surface_);
    api_.destroy_context(display_, context_);
  }

  void make_current() override {
    if (!api_.make_current(display_, surface_, surface_, context_))
      throw GlError("eglMakeCurrent failed on EGL device " + std::to_string(device_) + " (error " +
                    hex(api_.get_error()) + ")");
    std::call_once(api_.functions_loaded, [&] {
      const auto missing = gl::load(api_.functions, [](const char* name) -> gl::Proc {
        return reinterpret_cast<gl::Proc>(egl_api().get_proc(name));
      });
      if (!missing.empty()) throw GlError("EGL does not provide " + missing.front());
    });
    gl::current = &api_.functions;
  }

  std::string describe() const override {
    return "egl device " + std::to_string(device_) + " (" + vendor_ + ")";
  }

 private:
  EglApi& api_;
  int device_ = 0;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  EGLSurface surface_ = EGL_NO_SURFACE;
  std::string vendor_;
};

}  // namespace

std::unique_ptr<BackendContext> make_egl_context(int device, int major, int minor) {
  return std::make_unique<EglContext>(device, major, minor);
}

std::vector<EglDevice> list_egl_devices() {
  const EglApi& egl = egl_api();
  std::vector<EglDevice> out;
  const std::vector<EGLDeviceEXT> devices = egl.devices();
  for (std::size_t i = 0; i < devices.size(); ++i) {
    EglDevice d;
    d.index = int(i);
    const char* ext = egl.query_device_string(devices[i], EGL_EXTENSIONS);
    d.extensions = ext ? ext : "";
    d.software = is_software(egl, devices[i]);
    if (has_extension(ext, "EGL_EXT_device_drm")) {
      const char* file = egl.query_device_string(devices[i], EGL_DRM_DEVICE_FILE_EXT);
      d.drm_file = file ? file : "";
    }
    try {
      const EGLDisplay display = egl.display(devices[i], "EGL device " + std::to_string(i));
      const char* vendor = egl.query_string(display, EGL_VENDOR);
      d.vendor = vendor ? vendor : "";
    } catch (const GlError& e) {
      d.vendor = std::string("(") + e.what() + ")";
    }
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace render
