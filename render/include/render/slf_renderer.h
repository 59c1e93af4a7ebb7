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
// Three ways to shade (SlfShading), one image up to where each texel's direction is taken:
//  - one pass: the fragment shader of the mesh's own pass reconstructs;
//  - deferred: the mesh is first drawn with a trivial shader writing its atlas coordinates
//    (and depth), then one screen-sized triangle, depth-tested against it, shades the covered
//    pixels, the direction from the pixel's ray. llvmpipe shades in 4 x 4 blocks, so a mesh
//    of 5-pixel triangles (the bunny at 1280 x 948) costs the one-pass shader several blocks
//    a triangle;
//  - texture space: the reconstruction runs once per texel into a radiance map of the
//    surface map's size, each texel toward the eye from its own surface point (the paper's
//    per-texel direction, slf_radiance_toward), then the mesh's pass reads that map with one
//    bilinear fetch (the same spatial blend by linearity; negatives clamped after it). Only
//    the 8 x 8 blocks of texels that some triangle in view and facing the eye can read are
//    shaded: per block, a cone bounding the normals of the triangles that read it and a
//    sphere bounding those triangles, tested on the CPU every frame. The cost follows the
//    texels in view instead of the pixels covered: at a 256 x 256 map (prtr slf's default)
//    an order of magnitude fewer reconstructions than a 1280 x 948 frame of the bunny.
// The automatic choice (the default) shades in texture space when the texels to shade are no
// more than the fragments the last frame's mesh shaded (a sample query; before the first
// frame, the frame's pixels), and otherwise on the screen: deferred on a software rasterizer,
// one pass on a GPU.
// A grid of reflected directions (prt/slf_directions.h) mirrors each texel's view about
// that texel's own normal (an RGBA32F normal map beside the weights), so the four texels of
// a fragment have four places in the view maps: the screen paths then reconstruct them one
// at a time (no shared-cluster sum), and texture space mirrors each texel's own direction.
//
// Precision: on Mesa's rasterisers the filter weights are single floats; a hardware GPU's
// texture units may quantise them (8 fractional bits on many), which rounds the
// interpolation between neighbouring directions by up to 1/512 of their difference.
#pragma once

#include "common/enum_names.h"
#include "probes/probe.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"
#include "render/slf_model.h"

#include <memory>

namespace render {

enum class SlfShading { kAutomatic, kOnePass, kDeferred, kTextureSpace };
inline constexpr auto kSlfShadingNames = common::enum_table<SlfShading>(
    "surface light field shading", {{SlfShading::kAutomatic, "auto"},
                                    {SlfShading::kOnePass, "one-pass"},
                                    {SlfShading::kDeferred, "deferred"},
                                    {SlfShading::kTextureSpace, "texture-space"}});

struct SlfRendererOptions {
  bool cull_back_faces = true;  // closed meshes; the SLF of a face seen from behind is not stored
  // Sum the texels cluster by cluster (see above); false reconstructs each of the four
  // texels on its own, to measure the difference.
  bool shared_cluster_fast_path = true;
  // Where the reconstruction runs (see above); automatic: chosen per frame by its cost.
  SlfShading shading = SlfShading::kAutomatic;
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
  // How the last frame was shaded, never kAutomatic (before the first frame: texture space
  // for the automatic choice, else the option as this context resolves it).
  SlfShading shading() const;
  // Texels the last frame shaded in texture space (its blocks in view, 64 each; 0 on a
  // screen path), and the texels of every block some triangle reads.
  long long texels_shaded() const;
  long long texels_in_blocks() const;
  void set_probe(const probes::Probe* probe);
  void set_options(const SlfRendererOptions& options);
  const SlfRendererOptions& options() const;

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
