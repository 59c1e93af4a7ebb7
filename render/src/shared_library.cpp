#include "shared_library.h"

#include "render/gl_context.h"

#include <dlfcn.h>

namespace render {

SharedLibrary::SharedLibrary(std::initializer_list<const char*> names) {
  std::string errors;
  for (const char* n : names) {
    handle_ = dlopen(n, RTLD_NOW | RTLD_LOCAL);
    if (handle_) {
      name_ = n;
      return;
    }
    const char* e = dlerror();
    errors += errors.empty() ? "" : "; ";
    errors += e ? e : n;
  }
  throw GlError("cannot load " + std::string(*names.begin()) + " (" + errors + ")");
}

void* SharedLibrary::symbol(const char* name) const {
  return dlsym(handle_, name);
}

}  // namespace render
