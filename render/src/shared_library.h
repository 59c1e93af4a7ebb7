// render/src/shared_library.h (private): a library opened at run time (dlopen). The GL
// backends open libOSMesa and libEGL this way, so a binary starts without either and needs
// only the one it uses: render_bench runs on a GPU machine that has no OSMesa.
#pragma once

#include <string>

namespace render {

class SharedLibrary {
 public:
  // Opens the first of `names` that loads (RTLD_LOCAL: its GL symbols stay out of the global
  // namespace, where OSMesa's and glvnd's would collide); throws GlError naming each
  // candidate's dlerror when none does.
  explicit SharedLibrary(std::initializer_list<const char*> names);
  // Never unloaded: GL drivers keep thread-local state and exit handlers that outlive any
  // context, and Mesa does not support being unloaded. Instances are process-wide statics.
  ~SharedLibrary() = default;
  SharedLibrary(const SharedLibrary&) = delete;
  SharedLibrary& operator=(const SharedLibrary&) = delete;

  // The symbol's address, or null.
  void* symbol(const char* name) const;
  const std::string& name() const { return name_; }

 private:
  void* handle_ = nullptr;
  std::string name_;
};

}  // namespace render
