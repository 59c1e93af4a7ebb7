// The offscreen context exists, is the core profile we asked for, and draws: a clear colour
// read back from a framebuffer object proves the context is current and working (an EGL
// context has no default buffer). The backend comes from PRTR_GL, so CTest runs these under
// OSMesa and again under EGL; the selection tests name their backend explicitly.
#include "render/gl_context.h"

#include "gl_api.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

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
  GLuint fbo = 0, colour = 0;
  glGenFramebuffers(1, &fbo);
  glGenRenderbuffers(1, &colour);
  glBindRenderbuffer(GL_RENDERBUFFER, colour);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 4, 4);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
  ASSERT_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
  glViewport(0, 0, 4, 4);
  glClearColor(0.f, 1.f, 0.f, 1.f);
  glClear(GL_COLOR_BUFFER_BIT);
  unsigned char px[4] = {0, 0, 0, 0};
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(1, 1, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
  render::check_gl("readback");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteRenderbuffers(1, &colour);
  glDeleteFramebuffers(1, &fbo);
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

TEST(GlBackend, NamesRoundTrip) {
  for (render::GlBackend b : {render::GlBackend::kOsmesa, render::GlBackend::kEgl})
    EXPECT_EQ(render::parse_gl_backend(render::gl_backend_name(b)), b);
  EXPECT_FALSE(render::parse_gl_backend("foo"));
  EXPECT_FALSE(render::parse_gl_backend("EGL"));
  EXPECT_FALSE(render::parse_gl_backend(""));
}

// Sets an environment variable for one scope, restoring what was there.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() { had_ ? ::setenv(name_, old_.c_str(), 1) : ::unsetenv(name_); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

TEST(GlBackend, EnvironmentSelects) {
  {
    ScopedEnv gl("PRTR_GL", "egl"), dev("PRTR_GL_DEVICE", "0");
    const render::GlSelection s = render::gl_selection_from_environment();
    EXPECT_EQ(s.backend, render::GlBackend::kEgl);
    EXPECT_EQ(s.device, 0);
  }
  {
    ScopedEnv gl("PRTR_GL", ""), dev("PRTR_GL_DEVICE", "");
    const render::GlSelection s = render::gl_selection_from_environment();
    EXPECT_EQ(s.backend, render::GlBackend::kOsmesa);
    EXPECT_EQ(s.device, -1);
  }
  {
    ScopedEnv gl("PRTR_GL", "vulkan");
    try {
      render::gl_selection_from_environment();
      ADD_FAILURE() << "PRTR_GL=vulkan accepted";
    } catch (const render::GlError& e) {
      EXPECT_NE(std::string(e.what()).find("PRTR_GL=vulkan"), std::string::npos) << e.what();
    }
  }
  for (const char* bad : {"-1", "x", "1x", "99999"}) {
    ScopedEnv dev("PRTR_GL_DEVICE", bad);
    EXPECT_THROW(render::gl_selection_from_environment(), render::GlError) << bad;
  }
}

// Mesa's EGL lists its software device (EGL_MESA_device_software) where no GPU is.
TEST(GlBackend, EglListsDevicesAndCreatesOnEach) {
  const std::vector<render::EglDevice> devices = render::list_egl_devices();
  ASSERT_FALSE(devices.empty());
  for (const render::EglDevice& d : devices) {
    EXPECT_EQ(d.index, &d - devices.data());
    EXPECT_FALSE(d.extensions.empty());
    render::GlContext ctx({render::GlBackend::kEgl, d.index});
    EXPECT_EQ(ctx.backend(), render::GlBackend::kEgl);
    EXPECT_NE(ctx.description().find("egl device " + std::to_string(d.index)), std::string::npos)
        << ctx.description();
    EXPECT_TRUE(ctx.info().core_profile);
  }
}

TEST(GlBackend, EglDeviceOutOfRangeSaysSoAndHowToUseOsmesa) {
  const int count = int(render::list_egl_devices().size());
  try {
    render::GlContext ctx({render::GlBackend::kEgl, count});
    ADD_FAILURE() << "device " << count << " accepted";
  } catch (const render::GlError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("does not exist"), std::string::npos) << m;
    EXPECT_NE(m.find("--gl osmesa"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

// Both backends live in one process: a context of each, made current in turn, draws with its
// own entry points.
TEST(GlBackend, OsmesaAndEglContextsAlternate) {
  render::GlContext osmesa({render::GlBackend::kOsmesa});
  render::GlContext egl({render::GlBackend::kEgl});
  EXPECT_EQ(osmesa.backend(), render::GlBackend::kOsmesa);
  for (int round = 0; round < 2; ++round) {
    osmesa.make_current();
    EXPECT_TRUE(osmesa.info().core_profile);
    egl.make_current();
    EXPECT_TRUE(egl.info().core_profile);
  }
}

}  // namespace
