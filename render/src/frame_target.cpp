#include "frame_target.h"

#include "render/gl_context.h"

#include <algorithm>
#include <string>
#include <vector>

namespace render {

FrameTarget::~FrameTarget() {
  glDeleteFramebuffers(1, &fbo_);
  glDeleteRenderbuffers(1, &colour_);
  glDeleteRenderbuffers(1, &depth_);
}

void FrameTarget::bind(int width, int height, bool half) {
  if (!fbo_ || width != width_ || height != height_ || half != half_) {
    if (!fbo_) {
      glGenFramebuffers(1, &fbo_);
      glGenRenderbuffers(1, &colour_);
      glGenRenderbuffers(1, &depth_);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, colour_);
    glRenderbufferStorage(GL_RENDERBUFFER, half ? GL_RGBA16F : GL_RGBA32F, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
      throw GlError("framebuffer " + std::to_string(width) + " x " + std::to_string(height) +
                    " RGBA32F + depth is incomplete (status " + std::to_string(status) +
                    "); try a smaller --width/--height");
    check_gl("Renderer: framebuffer");
    width_ = width;
    height_ = height;
    half_ = half;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glViewport(0, 0, width, height);
}

Image FrameTarget::read() const {
  Image image;
  read(image);
  return image;
}

void FrameTarget::read(Image& image) const {
  // An unbound target would read the default framebuffer: whatever the context last showed.
  if (empty()) throw GlError("reading a frame: nothing rendered yet; call render() first");
  image.width = width_;
  image.height = height_;
  image.rgba.resize(std::size_t(image.width) * image.height * 4);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, image.width, image.height, GL_RGBA, GL_FLOAT, image.rgba.data());
  check_gl("Renderer::read_image");
  // GL's row 0 is the bottom one: swap rows in place (no second frame-sized buffer).
  const std::size_t row = std::size_t(image.width) * 4;
  for (int y = 0; y < image.height / 2; ++y)
    std::swap_ranges(image.rgba.begin() + std::ptrdiff_t(std::size_t(y) * row),
                     image.rgba.begin() + std::ptrdiff_t(std::size_t(y + 1) * row),
                     image.rgba.begin() + std::ptrdiff_t(std::size_t(image.height - 1 - y) * row));
}

}  // namespace render
