// viewer/frame_source.h: what `prtr view`'s server renders with. The server's render thread
// hands each queued ViewState to one FrameSource and sends back what it returns; a relit PRT
// set (viewer/scene.h) and a surface light field (viewer/slf_scene.h) are the two, and the
// server does not know which it holds.
#pragma once

#include "viewer/frame.h"
#include "viewer/request.h"

#include <memory>

namespace viewer {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Called on the thread that made the source (its GL context is current there). Never
  // throws for a bad state: request_error (HTTP 400) or server_error (500) says what went
  // wrong, and the image is empty then.
  virtual std::shared_ptr<RenderedFrame> render(const ViewState& state) = 0;
};

}  // namespace viewer
