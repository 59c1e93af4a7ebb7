// render/floor_harness.h: the llvmpipe floor of the render benchmark
// (bench/render_bench.cpp). Draws a mesh with a
// trivial shader (position only, constant colour) into the same RGBA32F + depth framebuffer
// the renderer uses, so a mode's frame time can be reported as a ratio to what the
// rasteriser alone costs on this machine.
#pragma once

#include "meshes/mesh.h"
#include "probes/probe.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"

#include <vector>

namespace render {

struct FloorOptions {
  bool cull_back_faces = true;
  bool optimize_vertex_cache = true;
  int frames = 20, warmup = 3;
  // The renderer's probe background pass, drawn first in place of the colour clear as the
  // renderer draws it, so the floor has the same passes over the framebuffer as a real frame
  // (like-for-like ratios); null = mesh only.
  const probes::Probe* background = nullptr;
  // When set, the pipeline statistics of the last frame's draws (RenderStats::pass_work).
  std::vector<PassWork>* work = nullptr;
  // When set, the last frame's image (what every timed frame drew, or should have).
  Image* last_frame = nullptr;
};

// Median milliseconds of one clear + draw + glFinish. Needs a current GL context.
double floor_frame_ms(const meshes::Mesh& mesh, const Camera& camera,
                      const FloorOptions& options = {});

}  // namespace render
