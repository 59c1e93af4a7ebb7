// render/src/gl_api.h (private): every OpenGL entry point render/ calls, reached through
// function pointers that the current context's backend resolved (OSMesaGetProcAddress or
// eglGetProcAddress). libOSMesa and glvnd's libOpenGL both export `glClear` and friends, and
// a call bound at link time reaches only one of them; so nothing here links to either, and
// `glClear(...)` in render/ expands to a call through the table of the backend whose context
// is current on this thread. A new GL call in render/ needs its name in both lists below
// (a missing #define fails the link: no library provides the symbol any more).
#pragma once

// The prototypes are declarations only, used for the pointer types (decltype); no object
// refers to the symbols themselves.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <string>
#include <vector>

#define PRTR_GL_FUNCTIONS(X)     \
  X(glActiveTexture)             \
  X(glAttachShader)              \
  X(glBeginQuery)                \
  X(glBeginTransformFeedback)    \
  X(glBindBuffer)                \
  X(glBindBufferBase)            \
  X(glBindBufferRange)           \
  X(glBindFramebuffer)           \
  X(glBindRenderbuffer)          \
  X(glBindTexture)               \
  X(glBindVertexArray)           \
  X(glBlendFunc)                 \
  X(glBufferData)                \
  X(glBufferSubData)             \
  X(glCheckFramebufferStatus)    \
  X(glClear)                     \
  X(glClearColor)                \
  X(glClearDepth)                \
  X(glColorMask)                 \
  X(glCompileShader)             \
  X(glCreateProgram)             \
  X(glCreateShader)              \
  X(glCullFace)                  \
  X(glDebugMessageCallback)      \
  X(glDebugMessageControl)       \
  X(glDeleteBuffers)             \
  X(glDeleteFramebuffers)        \
  X(glDeleteProgram)             \
  X(glDeleteQueries)             \
  X(glDeleteRenderbuffers)       \
  X(glDeleteShader)              \
  X(glDeleteTextures)            \
  X(glDeleteVertexArrays)        \
  X(glDepthFunc)                 \
  X(glDepthMask)                 \
  X(glDisable)                   \
  X(glDisableVertexAttribArray)  \
  X(glDispatchCompute)           \
  X(glDrawArrays)                \
  X(glDrawArraysInstanced)       \
  X(glDrawBuffers)               \
  X(glDrawElements)              \
  X(glEnable)                    \
  X(glEnableVertexAttribArray)   \
  X(glEndQuery)                  \
  X(glEndTransformFeedback)      \
  X(glFinish)                    \
  X(glFlush)                     \
  X(glFramebufferRenderbuffer)   \
  X(glFramebufferTexture2D)      \
  X(glFrontFace)                 \
  X(glGenBuffers)                \
  X(glGenFramebuffers)           \
  X(glGenQueries)                \
  X(glGenRenderbuffers)          \
  X(glGenTextures)               \
  X(glGenVertexArrays)           \
  X(glGetBufferSubData)          \
  X(glGetError)                  \
  X(glGetInteger64v)             \
  X(glGetIntegerv)               \
  X(glGetProgramInfoLog)         \
  X(glGetProgramiv)              \
  X(glGetQueryObjectui64v)       \
  X(glGetQueryObjectuiv)         \
  X(glGetShaderInfoLog)          \
  X(glGetShaderiv)               \
  X(glGetString)                 \
  X(glGetUniformLocation)        \
  X(glLinkProgram)               \
  X(glMemoryBarrier)             \
  X(glPixelStorei)               \
  X(glReadBuffer)                \
  X(glReadPixels)                \
  X(glRenderbufferStorage)       \
  X(glShaderSource)              \
  X(glTexImage2D)                \
  X(glTexImage3D)                \
  X(glTexParameteri)             \
  X(glTransformFeedbackVaryings) \
  X(glUniform1i)                 \
  X(glUniform1ui)                \
  X(glUniform2f)                 \
  X(glUniform3f)                 \
  X(glUniform3fv)                \
  X(glUniformMatrix3fv)          \
  X(glUniformMatrix4fv)          \
  X(glUseProgram)                \
  X(glVertexAttribDivisor)       \
  X(glVertexAttribIPointer)      \
  X(glVertexAttribPointer)       \
  X(glViewport)

namespace render::gl {

struct Functions {
#define PRTR_GL_MEMBER(name) decltype(&::name) name = nullptr;
  PRTR_GL_FUNCTIONS(PRTR_GL_MEMBER)
#undef PRTR_GL_MEMBER
};

// The table of the backend whose context was last made current on this thread (per thread,
// as GL's current context is); null before any.
extern thread_local const Functions* current;

// Resolves every entry point through `get_proc`; returns the names it could not resolve
// (empty on success), so a backend can refuse a context that lacks one.
using Proc = void (*)();
using GetProc = Proc (*)(const char* name);
std::vector<std::string> load(Functions& table, GetProc get_proc);

}  // namespace render::gl

// gl_api.cpp fills the tables by member name, so it sees the names unexpanded.
#ifndef PRTR_GL_API_NO_MACROS
// clang-format off
#define glActiveTexture (::render::gl::current->glActiveTexture)
#define glAttachShader (::render::gl::current->glAttachShader)
#define glBeginQuery (::render::gl::current->glBeginQuery)
#define glBeginTransformFeedback (::render::gl::current->glBeginTransformFeedback)
#define glBindBuffer (::render::gl::current->glBindBuffer)
#define glBindBufferBase (::render::gl::current->glBindBufferBase)
#define glBindBufferRange (::render::gl::current->glBindBufferRange)
#define glBindFramebuffer (::render::gl::current->glBindFramebuffer)
#define glBindRenderbuffer (::render::gl::current->glBindRenderbuffer)
#define glBindTexture (::render::gl::current->glBindTexture)
#define glBindVertexArray (::render::gl::current->glBindVertexArray)
#define glBlendFunc (::render::gl::current->glBlendFunc)
#define glBufferData (::render::gl::current->glBufferData)
#define glBufferSubData (::render::gl::current->glBufferSubData)
#define glCheckFramebufferStatus (::render::gl::current->glCheckFramebufferStatus)
#define glClear (::render::gl::current->glClear)
#define glClearColor (::render::gl::current->glClearColor)
#define glClearDepth (::render::gl::current->glClearDepth)
#define glColorMask (::render::gl::current->glColorMask)
#define glCompileShader (::render::gl::current->glCompileShader)
#define glCreateProgram (::render::gl::current->glCreateProgram)
#define glCreateShader (::render::gl::current->glCreateShader)
#define glCullFace (::render::gl::current->glCullFace)
#define glDebugMessageCallback (::render::gl::current->glDebugMessageCallback)
#define glDebugMessageControl (::render::gl::current->glDebugMessageControl)
#define glDeleteBuffers (::render::gl::current->glDeleteBuffers)
#define glDeleteFramebuffers (::render::gl::current->glDeleteFramebuffers)
#define glDeleteProgram (::render::gl::current->glDeleteProgram)
#define glDeleteQueries (::render::gl::current->glDeleteQueries)
#define glDeleteRenderbuffers (::render::gl::current->glDeleteRenderbuffers)
#define glDeleteShader (::render::gl::current->glDeleteShader)
#define glDeleteTextures (::render::gl::current->glDeleteTextures)
#define glDeleteVertexArrays (::render::gl::current->glDeleteVertexArrays)
#define glDepthFunc (::render::gl::current->glDepthFunc)
#define glDepthMask (::render::gl::current->glDepthMask)
#define glDisable (::render::gl::current->glDisable)
#define glDisableVertexAttribArray (::render::gl::current->glDisableVertexAttribArray)
#define glDispatchCompute (::render::gl::current->glDispatchCompute)
#define glDrawArrays (::render::gl::current->glDrawArrays)
#define glDrawArraysInstanced (::render::gl::current->glDrawArraysInstanced)
#define glDrawBuffers (::render::gl::current->glDrawBuffers)
#define glDrawElements (::render::gl::current->glDrawElements)
#define glEnable (::render::gl::current->glEnable)
#define glEnableVertexAttribArray (::render::gl::current->glEnableVertexAttribArray)
#define glEndQuery (::render::gl::current->glEndQuery)
#define glEndTransformFeedback (::render::gl::current->glEndTransformFeedback)
#define glFinish (::render::gl::current->glFinish)
#define glFlush (::render::gl::current->glFlush)
#define glFramebufferRenderbuffer (::render::gl::current->glFramebufferRenderbuffer)
#define glFramebufferTexture2D (::render::gl::current->glFramebufferTexture2D)
#define glFrontFace (::render::gl::current->glFrontFace)
#define glGenBuffers (::render::gl::current->glGenBuffers)
#define glGenFramebuffers (::render::gl::current->glGenFramebuffers)
#define glGenQueries (::render::gl::current->glGenQueries)
#define glGenRenderbuffers (::render::gl::current->glGenRenderbuffers)
#define glGenTextures (::render::gl::current->glGenTextures)
#define glGenVertexArrays (::render::gl::current->glGenVertexArrays)
#define glGetBufferSubData (::render::gl::current->glGetBufferSubData)
#define glGetError (::render::gl::current->glGetError)
#define glGetInteger64v (::render::gl::current->glGetInteger64v)
#define glGetIntegerv (::render::gl::current->glGetIntegerv)
#define glGetProgramInfoLog (::render::gl::current->glGetProgramInfoLog)
#define glGetProgramiv (::render::gl::current->glGetProgramiv)
#define glGetQueryObjectui64v (::render::gl::current->glGetQueryObjectui64v)
#define glGetQueryObjectuiv (::render::gl::current->glGetQueryObjectuiv)
#define glGetShaderInfoLog (::render::gl::current->glGetShaderInfoLog)
#define glGetShaderiv (::render::gl::current->glGetShaderiv)
#define glGetString (::render::gl::current->glGetString)
#define glGetUniformLocation (::render::gl::current->glGetUniformLocation)
#define glLinkProgram (::render::gl::current->glLinkProgram)
#define glMemoryBarrier (::render::gl::current->glMemoryBarrier)
#define glPixelStorei (::render::gl::current->glPixelStorei)
#define glReadBuffer (::render::gl::current->glReadBuffer)
#define glReadPixels (::render::gl::current->glReadPixels)
#define glRenderbufferStorage (::render::gl::current->glRenderbufferStorage)
#define glShaderSource (::render::gl::current->glShaderSource)
#define glTexImage2D (::render::gl::current->glTexImage2D)
#define glTexImage3D (::render::gl::current->glTexImage3D)
#define glTexParameteri (::render::gl::current->glTexParameteri)
#define glTransformFeedbackVaryings (::render::gl::current->glTransformFeedbackVaryings)
#define glUniform1i (::render::gl::current->glUniform1i)
#define glUniform1ui (::render::gl::current->glUniform1ui)
#define glUniform2f (::render::gl::current->glUniform2f)
#define glUniform3f (::render::gl::current->glUniform3f)
#define glUniform3fv (::render::gl::current->glUniform3fv)
#define glUniformMatrix3fv (::render::gl::current->glUniformMatrix3fv)
#define glUniformMatrix4fv (::render::gl::current->glUniformMatrix4fv)
#define glUseProgram (::render::gl::current->glUseProgram)
#define glVertexAttribDivisor (::render::gl::current->glVertexAttribDivisor)
#define glVertexAttribIPointer (::render::gl::current->glVertexAttribIPointer)
#define glVertexAttribPointer (::render::gl::current->glVertexAttribPointer)
#define glViewport (::render::gl::current->glViewport)
// clang-format on
#endif
