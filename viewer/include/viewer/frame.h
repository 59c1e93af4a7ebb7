// viewer/frame.h: what `prtr view`'s render thread hands back for one job: the linear
// image, the overlay picture when asked, the renderer's statistics, or the reason the state
// could not be rendered. Encoded to JPEG once, by whichever request thread gets it first
// (several coalesced requests share one frame).
#pragma once

#include "render/false_colour.h"
#include "render/image.h"
#include "viewer/request.h"

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace viewer {

struct FrameStats {
  const char* kind = "prt";  // what drew it: "prt" (modes, passes) or "slf" (one pass, baked light)
  double queue_ms = 0;       // submitted -> taken by the render thread
  double render_ms = 0;      // renderer set-up (if any) + frame + read-back
  double frame_ms = 0;       // Renderer::render alone (what render_bench times)
  double readback_ms = 0;    // Renderer::read_image: the float framebuffer to memory
  double cpu_ms = 0, gl_ms = 0;
  double overlay_ms = 0;  // CPU false-colour picture
  double setup_ms = 0;    // a new renderer (grouping, upload) or probe, when this frame needed one
  int passes = 1, clusters_per_pass = 0, register_budget = 0;
  double average_overdraw = 1;
  int requests = 1;  // requests this frame answers (1 + coalesced)
  // The difference overlay's relative luminance difference from the uncompressed frame.
  double difference_rms = 0, difference_max = 0;
  // The compression shown, and the asked-for one when it differs (viewer/compressions.h).
  int clusters = 0, pcs = 0, order = 0;
  bool compressing = false;
  double compress_progress = 0;
  std::string compress_error;
};

struct RenderedFrame {
  ViewState state;  // as rendered (the newest of the coalesced requests)
  render::Image image;
  std::optional<render::Picture> overlay;
  double overlay_opacity = 0.65;  // the difference view is shown opaque
  FrameStats stats;
  std::string request_error;  // the state cannot be rendered (HTTP 400); image empty
  std::string server_error;   // rendering failed (HTTP 500); image empty

  // Filled once by the first request thread that sends the frame.
  mutable std::once_flag encoded;
  mutable std::vector<std::uint8_t> jpeg;
  mutable double encode_ms = 0;
};

}  // namespace viewer
