// render/slf_renderer.h: a compressed surface light field drawn in one GL pass (SLF paper,
// Secs. 3.3 and 4): per fragment, the four surface-map texels around the atlas coordinate,
// each reconstructed in its own cluster from that cluster's view maps at the view direction,
// bilinear in space and in direction exactly as render/slf_reference.h computes it on the CPU
// (tests hold the two to float rounding). No super-clusters: a fragment can read any cluster,
// so every triangle is drawn once.
//
// Textures: the cluster id per texel (R32I, the four around a fragment in one gather); the
// surface map's weights (RGBA32F array, four components a layer); the view maps as one
// RGBA32F array whose layers tile the clusters' Z x W maps, each tile with a one-texel gutter
// (azimuth wrapped around, poles clamped) so that the hardware's bilinear filter interpolates
// direction, seam included, in one fetch per texel; a direction's 3 (k + 1) floats (slice 0
// the mean, 1 + j component j, RGB each) are packed four a texel across the layers, so a
// cluster costs ceil(3 (k + 1) / 4) view fetches (7 at k = 8). A tile's corner follows from
// the cluster id by arithmetic (a division by the tiles per row), which costs less than the
// dependent fetch of the paper's cluster-map texture.
//
// The four texels are summed cluster by cluster: the fragment loops over the distinct
// clusters among them, interpolating the weights of each cluster's texels first and reading
// its view maps once; where the four share a cluster (all but the fragments on cluster
// borders) that is one iteration, the view fetches of one texel instead of four, the same
// sum by linearity. A loop, not an if: llvmpipe runs both sides of a branch for its whole
// SIMD group, but leaves a loop once no lane needs another iteration.
//
// Deferred option: the mesh is first drawn with a trivial shader writing its atlas
// coordinates (and depth), then one screen-sized triangle, depth-tested against it, shades
// the covered pixels, the direction from the pixel's ray. The same reconstruction, but
// llvmpipe shades in 4 x 4 blocks, so a mesh of 5-pixel triangles (the bunny at 1280 x 948)
// costs the one-pass shader several blocks a triangle; shading once per covered pixel halves
// the frame there (bench/slf_bench.cpp).
//
// Precision: on Mesa's rasterisers the filter weights are single floats; a hardware GPU's
// texture units may quantise them (8 fractional bits on many), which rounds the
// interpolation between neighbouring directions by up to 1/512 of their difference.
#pragma once

#include "probes/probe.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"
#include "render/slf_model.h"

#include <memory>
#include <optional>

namespace render {

struct SlfRendererOptions {
  bool cull_back_faces = true;  // closed meshes; the SLF of a face seen from behind is not stored
  // Sum the texels cluster by cluster (see above); false reconstructs each of the four
  // texels on its own, to measure the difference.
  bool shared_cluster_fast_path = true;
  // Shade after a uv pre-pass instead of in the mesh's own pass (see above). Unset: the
  // context decides, deferred on a software rasterizer (llvmpipe shades whole 4 x 4 blocks,
  // so small triangles cost the one-pass shader several times their pixels), one pass on a
  // GPU. The image is the same either way.
  std::optional<bool> deferred{};
};

class SlfRenderer {
 public:
  // Needs a current GL 4.5 context (render/gl_context.h). The model is validated and uploaded
  // (not kept). `probe` (may be null) is the background, drawn unrotated: the light field was
  // computed under the probe as it is, so turning the environment would not relight it.
  // GlError when a texture exceeds the context's limits (the message names the size).
  SlfRenderer(const SlfModel& model, const probes::Probe* probe,
              const SlfRendererOptions& options = {});
  ~SlfRenderer();
  SlfRenderer(const SlfRenderer&) = delete;
  SlfRenderer& operator=(const SlfRenderer&) = delete;

  // The probe (when there is one and use_probe is set) or the solid colour behind the mesh.
  void set_background(const Background& background);
  // Whether frames are shaded after a uv pre-pass: the option, or the context's choice.
  bool deferred() const;
  void set_probe(const probes::Probe* probe);
  void set_options(const SlfRendererOptions& options);

  // Draws one frame (background, then the mesh in one pass; waits with glFinish).
  FrameTiming render(const Camera& camera);
  // The last frame, linear RGB radiance, alpha coverage, row 0 at the top.
  Image read_image() const;
  void read_image(Image& into) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct SlfImageOptions {
  SlfRendererOptions renderer{};
  Background background{};  // use_probe: the probe passed in, when not null
  int supersample = 1;      // render at this factor per side and box-filter back (>= 1)
};

// "Render this model from this camera": one frame into a linear HDR image (RGB radiance,
// alpha coverage). Needs a current GL context. std::invalid_argument for a bad camera,
// model or supersampling factor.
Image render_slf_image(const SlfModel& model, const Camera& camera, const probes::Probe* probe,
                       const SlfImageOptions& options = {});

}  // namespace render
