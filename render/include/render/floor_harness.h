// render/floor_harness.h: the llvmpipe floor of the render benchmark
// (bench/render_bench.cpp). Draws a mesh with a
// trivial shader (position only, constant colour) into the same RGBA32F + depth framebuffer
// the renderer uses, so a mode's frame time can be reported as a ratio to what the
// rasteriser alone costs on this machine.
#pragma once

#include "meshes/mesh.h"
#include "render/camera.h"

namespace render {

struct FloorOptions {
  bool cull_back_faces = true;
  bool optimize_vertex_cache = true;
  int frames = 20, warmup = 3;
};

// Median milliseconds of one clear + draw + glFinish. Needs a current GL context.
double floor_frame_ms(const meshes::Mesh& mesh, const Camera& camera,
                      const FloorOptions& options = {});

}  // namespace render
