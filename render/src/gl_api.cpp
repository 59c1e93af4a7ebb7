#define PRTR_GL_API_NO_MACROS 1
#include "gl_api.h"

namespace render::gl {

thread_local const Functions* current = nullptr;

std::vector<std::string> load(Functions& table, GetProc get_proc) {
  std::vector<std::string> missing;
  // A pointer to function converts to another pointer-to-function type and back losslessly;
  // each entry point is called only through its own prototype's type.
#define PRTR_GL_LOAD(name)                                              \
  table.name = reinterpret_cast<decltype(table.name)>(get_proc(#name)); \
  if (!table.name) missing.emplace_back(#name);
  PRTR_GL_FUNCTIONS(PRTR_GL_LOAD)
#undef PRTR_GL_LOAD
  return missing;
}

}  // namespace render::gl
