// The offscreen context exists, is the core profile we asked for, and draws: a clear colour
// read back from the default buffer proves the context is current and working.
#include "render/gl_context.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>

#include <gtest/gtest.h>

namespace {

TEST(GlContext, CreatesCore45WithUniformBudget) {
  render::GlContext ctx(4, 5, 8, 8);
  const render::GlInfo info = ctx.info();
  EXPECT_TRUE(info.major > 4 || (info.major == 4 && info.minor >= 5)) << info.version;
  EXPECT_TRUE(info.core_profile);
  // The thesis hardware offered 256 vec4 registers; llvmpipe offers far more.
  EXPECT_GE(info.max_vertex_uniform_vectors, 256);
  EXPECT_FALSE(info.renderer.empty());
}

TEST(GlContext, ClearReadsBack) {
  render::GlContext ctx(4, 5, 4, 4);
  glClearColor(0.f, 1.f, 0.f, 1.f);
  glClear(GL_COLOR_BUFFER_BIT);
  unsigned char px[4] = {0, 0, 0, 0};
  glReadPixels(1, 1, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
  render::check_gl("readback");
  EXPECT_EQ(px[0], 0);
  EXPECT_EQ(px[1], 255);
  EXPECT_EQ(px[2], 0);
}

TEST(GlContext, CheckGlReportsErrors) {
  render::GlContext ctx;
  glEnable(0xFFFF);  // GL_INVALID_ENUM
  EXPECT_THROW(render::check_gl("test"), render::GlError);
  EXPECT_NO_THROW(render::check_gl("after"));
}

}  // namespace
