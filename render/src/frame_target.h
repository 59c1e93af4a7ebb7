// render/src/frame_target.h (private): the offscreen RGBA32F + 32-bit float depth framebuffer
// every draw of the renderer goes to, (re)allocated when the camera's size changes.
#pragma once

#include "gl_program.h"
#include "render/image.h"

namespace render {

class FrameTarget {
 public:
  FrameTarget() = default;
  ~FrameTarget();
  FrameTarget(const FrameTarget&) = delete;
  FrameTarget& operator=(const FrameTarget&) = delete;

  // Binds the framebuffer at this size (allocating it first when the size changed) and sets
  // the viewport. GlError when the driver cannot provide it.
  // `half`: RGBA16F colour instead of RGBA32F (a change reallocates).
  void bind(int width, int height, bool half = false);
  bool empty() const { return fbo_ == 0; }
  // The colour buffer, row 0 at the top. GlError before the first bind (nothing rendered).
  Image read() const;
  // The same into `into`, whose storage is reused when it is large enough: a fresh 2 x 2
  // supersampled frame is 77 MB, and zeroing and faulting it in cost more than the read.
  void read(Image& into) const;

 private:
  GLuint fbo_ = 0, colour_ = 0, depth_ = 0;
  int width_ = 0, height_ = 0;
  bool half_ = false;
};

}  // namespace render
