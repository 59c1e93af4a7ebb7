#include "gl_program.h"

#include "render/gl_context.h"

#include <algorithm>
#include <sstream>
#include <vector>

namespace render {

namespace {

std::string shader_log(GLuint shader) {
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(std::size_t(std::max(length, 1)), '\0');
  glGetShaderInfoLog(shader, length, nullptr, log.data());
  return log.c_str();
}

// The source with line numbers, trimmed to the first lines the log mentions (GLSL logs name
// "0:LINE(COL)"), so a message stays readable for 1000-line generated shaders.
std::string excerpt(const std::string& source, const std::string& log) {
  int line = 0;
  const auto colon = log.find("0:");
  if (colon != std::string::npos) line = std::atoi(log.c_str() + colon + 2);
  std::istringstream in(source);
  std::ostringstream out;
  std::string text;
  for (int i = 1; std::getline(in, text); ++i)
    if (line == 0 ? i <= 12 : (i >= line - 3 && i <= line + 3))
      out << i << ": " << text.substr(0, 160) << "\n";
  return out.str();
}

GLuint compile(GLenum stage, const std::string& source, const std::string& name) {
  const GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = shader_log(shader);
    glDeleteShader(shader);
    throw GlError("GLSL compile error in " + name +
                  (stage == GL_VERTEX_SHADER    ? " (vertex)"
                   : stage == GL_COMPUTE_SHADER ? " (compute)"
                                                : " (fragment)") +
                  ":\n" + log + "source:\n" + excerpt(source, log));
  }
  return shader;
}

}  // namespace

GlProgram::GlProgram(const std::string& name, const std::string& vertex,
                     const std::string& fragment, bool capture_radiance) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex, name);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment, name);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  if (capture_radiance) {
    const char* varyings[] = {"v_radiance"};
    glTransformFeedbackVaryings(id_, 1, varyings, GL_INTERLEAVED_ATTRIBS);
  }
  link(name, {vs, fs});
}

GlProgram::GlProgram(const std::string& name, const std::string& compute) {
  const GLuint cs = compile(GL_COMPUTE_SHADER, compute, name);
  id_ = glCreateProgram();
  glAttachShader(id_, cs);
  link(name, {cs});
}

void GlProgram::link(const std::string& name, std::initializer_list<GLuint> shaders) {
  glLinkProgram(id_);
  for (GLuint shader : shaders) glDeleteShader(shader);
  GLint ok = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint length = 0;
    glGetProgramiv(id_, GL_INFO_LOG_LENGTH, &length);
    std::string log(std::size_t(std::max(length, 1)), '\0');
    glGetProgramInfoLog(id_, length, nullptr, log.data());
    glDeleteProgram(id_);
    id_ = 0;
    throw GlError("GLSL link error in " + name + ":\n" + std::string(log.c_str()));
  }
  check_gl(("linking " + name).c_str());
}

GlProgram::~GlProgram() {
  if (id_) glDeleteProgram(id_);
}

GlProgram::GlProgram(GlProgram&& other) noexcept
    : id_(other.id_), uniforms_(std::move(other.uniforms_)) {
  other.id_ = 0;
}

GlProgram& GlProgram::operator=(GlProgram&& other) noexcept {
  if (this != &other) {
    if (id_) glDeleteProgram(id_);
    id_ = other.id_;
    uniforms_ = std::move(other.uniforms_);
    other.id_ = 0;
  }
  return *this;
}

GLint GlProgram::uniform(const char* name) {
  auto it = uniforms_.find(name);
  if (it != uniforms_.end()) return it->second;
  const GLint location = glGetUniformLocation(id_, name);
  uniforms_.emplace(name, location);
  return location;
}

}  // namespace render
