// The OSMesa backend: Mesa's llvmpipe through libOSMesa, opened at run time.
#include "backend_context.h"
#include "gl_api.h"
#include "render/gl_context.h"
#include "shared_library.h"

#include <GL/osmesa.h>

#include <mutex>
#include <vector>

namespace render {
namespace {

// libOSMesa's entry points and the GL table resolved through it, once per process.
struct OsmesaApi {
  SharedLibrary lib{"libOSMesa.so.8", "libOSMesa.so"};
  decltype(&::OSMesaCreateContextAttribs) create =
      reinterpret_cast<decltype(create)>(lib.symbol("OSMesaCreateContextAttribs"));
  decltype(&::OSMesaDestroyContext) destroy =
      reinterpret_cast<decltype(destroy)>(lib.symbol("OSMesaDestroyContext"));
  decltype(&::OSMesaMakeCurrent) make_current =
      reinterpret_cast<decltype(make_current)>(lib.symbol("OSMesaMakeCurrent"));
  decltype(&::OSMesaGetProcAddress) get_proc =
      reinterpret_cast<decltype(get_proc)>(lib.symbol("OSMesaGetProcAddress"));
  gl::Functions functions;
  std::once_flag functions_loaded;

  OsmesaApi() {
    if (!create || !destroy || !make_current || !get_proc)
      throw GlError(lib.name() + " lacks OSMesaCreateContextAttribs (Mesa 12 or newer needed)");
  }
};

OsmesaApi& osmesa_api() {
  static OsmesaApi instance;  // throws on every call while the library cannot be loaded
  return instance;
}

class OsmesaContext final : public BackendContext {
 public:
  OsmesaContext(int major, int minor, int width, int height) : api_(osmesa_api()) {
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
    context_ = api_.create(attribs, nullptr);
    if (!context_) {
      throw GlError("OSMesa could not create an OpenGL " + std::to_string(major) + "." +
                    std::to_string(minor) +
                    " core context (is Mesa's llvmpipe installed? try LIBGL_ALWAYS_SOFTWARE=1 "
                    "or a newer libosmesa6)");
    }
    width_ = width;
    height_ = height;
    buffer_.assign(std::size_t(width) * height * 4, 0);
    make_current();
  }
  ~OsmesaContext() override { api_.destroy(context_); }

  void make_current() override {
    if (!api_.make_current(context_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_))
      throw GlError("OSMesaMakeCurrent failed");
    // OSMesaGetProcAddress answers Mesa's dispatch stubs, valid for any OSMesa context;
    // resolved once a context is current, as some loaders require.
    std::call_once(api_.functions_loaded, [&] {
      const auto missing = gl::load(api_.functions, [](const char* name) -> gl::Proc {
        return reinterpret_cast<gl::Proc>(osmesa_api().get_proc(name));
      });
      if (!missing.empty()) throw GlError("OSMesa does not provide " + missing.front());
    });
    gl::current = &api_.functions;
  }

  std::string describe() const override { return "osmesa"; }

 private:
  OsmesaApi& api_;
  OSMesaContext context_ = nullptr;
  std::vector<unsigned char> buffer_;
  int width_ = 0, height_ = 0;
};

}  // namespace

std::unique_ptr<BackendContext> make_osmesa_context(int major, int minor, int width, int height) {
  return std::make_unique<OsmesaContext>(major, minor, width, height);
}

}  // namespace render
