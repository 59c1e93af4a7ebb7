// render/src/gl_program.h (private): a linked GLSL program whose compile and link errors
// become GlError with the driver's log and the numbered source lines around the error.
#pragma once

#include "gl_api.h"

#include <initializer_list>
#include <string>
#include <unordered_map>

namespace render {

class GlProgram {
 public:
  GlProgram() = default;
  // `name` appears in error messages. With `capture_radiance`, `v_radiance` is declared as
  // the transform feedback output before linking.
  GlProgram(const std::string& name, const std::string& vertex, const std::string& fragment,
            bool capture_radiance = false);
  // A compute program.
  GlProgram(const std::string& name, const std::string& compute);
  ~GlProgram();
  GlProgram(GlProgram&& other) noexcept;
  GlProgram& operator=(GlProgram&& other) noexcept;
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;

  GLuint id() const { return id_; }
  void use() const { glUseProgram(id_); }
  // -1 when the uniform does not exist or was optimised away (GL then ignores the set).
  GLint uniform(const char* name);

 private:
  // Links the attached `shaders` and deletes them; GlError with the log on failure.
  void link(const std::string& name, std::initializer_list<GLuint> shaders);

  GLuint id_ = 0;
  std::unordered_map<std::string, GLint> uniforms_;
};

}  // namespace render
