// render/renderer.h: relights a CPCA-compressed mesh with OpenGL (OSMesa/llvmpipe) into an
// offscreen RGBA32F + depth framebuffer. Thesis ch. 3.2 and 4.1; docs/ARCHITECTURE.md
// "Rendering".
//
// Modes (all give the same image up to float rounding; tests hold them to it):
//  - multipass:    depth pre-pass, then one additive pass per super-cluster with GL_EQUAL
//                  depth. A pass binds only its clusters' constants (a UBO range within the
//                  register budget) and draws only the triangles touching its clusters
//                  (index buffers built once); vertices of other passes output zero, and
//                  since interpolation is linear the passes sum to the single-pass image.
//  - singlepass:   all clusters' constants in one SSBO, one draw; overdraw exactly 1.
//  - decoupled:    vertices are stored sorted by (pass, cluster). Each cluster's vertices
//                  are shaded once, as points, with that cluster's constants bound as a UBO
//                  range (so every register index is a literal), and transform feedback
//                  writes their radiance into one vertex buffer; then all triangles are
//                  drawn once with a pass-through shader. Overdraw 1, every vertex shaded
//                  once, whatever the budget.
//  - uncompressed: per-vertex exit vectors e_p = M_p l from the transfer set (CPU GEMMs,
//                  uploaded as an SSBO), SH evaluated in the vertex shader.
//  - cpu:          the per-vertex radiance computed on the CPU from the same constants
//                  (render/shading.h), drawn with a pass-through shader.
// Lighting: the renderer takes the unrotated SH lighting l and the environment rotation R;
// per frame it computes D(R) l (no re-projection) and the constants, in parallel.
// Background: the probe rotated by R (radiance toward w is probe(R^T w)) or a solid colour.
// Alpha is coverage. Back faces are culled by default (closed meshes; see the options).
#pragma once

#include "common/enum_names.h"

#include "cpca/compressed.h"
#include "cpca/supercluster.h"
#include "meshes/mesh.h"
#include "probes/probe.h"
#include "prt/projection.h"
#include "prt/transfer.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/shading.h"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace render {

enum class Mode { kMultipass, kSinglepass, kDecoupled, kUncompressed, kCpu };
// name(mode) gives "unknown" out of range; parse throws std::invalid_argument listing names.
inline constexpr auto kModeNames =
    common::enum_table<Mode>("render mode", {{Mode::kMultipass, "multipass"},
                                             {Mode::kSinglepass, "singlepass"},
                                             {Mode::kDecoupled, "decoupled"},
                                             {Mode::kUncompressed, "uncompressed"},
                                             {Mode::kCpu, "cpu"}});

// The colour target the passes add into. On a GPU, additive blending into RGBA32F runs at a
// sixth of RGBA16F's rate (0.99 against 6.3 G fragments/s measured on an H200), which bounds
// the thesis configuration near 300 FPS; half floats keep 11 significant bits, an error
// measured in docs/BENCHMARKS.md. On Mesa's software rasterisers the formats cost the same,
// so kAuto keeps 32-bit floats there and takes half floats on a hardware GPU.
enum class Accumulation { kAuto, kFloat32, kFloat16 };
inline constexpr auto kAccumulationNames =
    common::enum_table<Accumulation>("accumulation format", {{Accumulation::kAuto, "auto"},
                                                             {Accumulation::kFloat32, "rgba32f"},
                                                             {Accumulation::kFloat16, "rgba16f"}});
// What `wanted` means in the current GL context (kAuto resolved by its renderer's name).
Accumulation resolve_accumulation(Accumulation wanted);

// Where the per-frame lighting constants (render/shading.h) are computed for the GPU-shaded
// paths. On the CPU the products stream every cluster's transfer rows from memory each
// frame and upload the results; on a GPU one compute dispatch reads the rows from video
// memory and writes the constant buffer in place. llvmpipe runs that dispatch on the CPU
// slower than the CPU's own parallel products, so kAuto takes the GPU on hardware only, and
// only where the rows fit one shader storage block. The CPU-shaded path always uses the CPU.
enum class Constants { kAuto, kCpu, kGpu };
inline constexpr auto kConstantsNames = common::enum_table<Constants>(
    "constants", {{Constants::kAuto, "auto"}, {Constants::kCpu, "cpu"}, {Constants::kGpu, "gpu"}});

struct RendererOptions {
  Mode mode = Mode::kMultipass;
  Accumulation accumulation = Accumulation::kAuto;
  Constants constants = Constants::kAuto;
  // vec4 registers a pass may use; 0 = what the context offers
  // (GlInfo::default_register_budget).
  int register_budget = 0;
  // Clusters per pass; 0 = as many as the budget holds. More than the budget holds is an error.
  int clusters_per_pass = 0;
  // The grouping of clusters into passes (a strategy's output, cpca/supercluster.h); when
  // empty, passes are filled in cluster order.
  std::optional<cpca::SuperClusters> groups;
  bool cull_back_faces = true;        // halves raster cost; closed meshes only
  bool optimize_vertex_cache = true;  // meshoptimizer order per index buffer
  // Vertices numbered in each draw's first-use order (multipass: a block of copies per pass)
  // so llvmpipe shades each about once per draw; false keeps the earlier numbering (slot
  // order) to measure the difference.
  bool renumber_vertices = true;
  // Multipass: each pass first shades its own vertices as points into the radiance buffer
  // (transform feedback, cluster by cluster with only that cluster's part of the pass's
  // constants bound, so every register index is a literal), then draws its triangles
  // pass-through, the other passes' corners reading a zero copy. false shades in the
  // triangle draws' vertex stage (own and foreign corners alike), to measure the difference.
  bool multipass_feedback = true;
  bool count_primitives = false;  // GL_PRIMITIVES_GENERATED query per pass (slower)
  // Pipeline-statistics queries around every draw of a frame (RenderStats::pass_work).
  bool count_work = false;
};

struct Background {
  bool use_probe = true;  // else the solid colour
  Rgb colour = Rgb::Zero();
};

struct FrameTiming {
  double cpu_ms = 0;    // rotation, constants, per-vertex CPU work, buffer uploads
  double gl_ms = 0;     // draw calls until glFinish returns
  double total_ms = 0;  // the frame
};

// One draw of a frame counted by GL_ARB_pipeline_statistics_query. `referenced_vertices` is
// the distinct vertices the draw can reach, so vs_invocations / referenced_vertices is the
// vertex-shader work wasted by the driver's post-transform reuse (1 is ideal).
struct PassWork {
  std::string label;  // "depth", "shade 12", "feedback", "background", ...
  std::uint64_t vs_invocations = 0, primitives = 0, fs_invocations = 0;
  std::uint64_t referenced_vertices = 0;
};
struct WorkTotals {
  std::uint64_t vs_invocations = 0, primitives = 0, fs_invocations = 0;
  std::uint64_t referenced_vertices = 0;
  double vs_per_referenced_vertex = 0;
};
WorkTotals work_totals(const std::vector<PassWork>& passes);

struct RenderStats {
  int register_budget = 0;
  int registers_per_cluster = 0;
  int clusters_per_pass = 0;
  int passes = 1;                                 // shading passes (draws over triangles)
  std::vector<std::uint64_t> triangles_per_pass;  // predicted from cluster ids and grouping
  std::vector<std::uint64_t> measured_triangles;  // GL queries of the last frame (if enabled)
  std::vector<PassWork> pass_work;                // the last frame's, with count_work
  double average_overdraw = 1.0;
  std::uint64_t triangle_count = 0;
  std::uint64_t vertex_count = 0;
  Accumulation accumulation = Accumulation::kFloat32;  // as resolved for this context
  Constants constants = Constants::kCpu;               // as resolved for this path
};

class Renderer {
 public:
  // Needs a current GL 4.5 context (render/gl_context.h). The mesh needs frames. `set` is
  // required for every mode but uncompressed, `transfer` for uncompressed; both must match
  // the mesh's vertex count. `probe` (may be null: black) is the background and is kept by
  // reference only during construction (uploaded as a texture).
  Renderer(const meshes::Mesh& mesh, const cpca::CompressedSet* set,
           const prt::TransferSet* transfer, const probes::Probe* probe,
           const RendererOptions& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  void set_background(const Background& background);
  // Uploads another probe as the background (may be null: none), e.g. when a viewer switches
  // probes; like the constructor's, it is not kept. The lighting is render()'s argument.
  void set_probe(const probes::Probe* probe);
  // RendererOptions::count_work for the following frames (timing frames leave it off so the
  // queries cost nothing there).
  void set_count_work(bool on);
  // RendererOptions::count_primitives for the following frames, likewise: a query per pass
  // makes multipass draw pass by pass instead of in one call.
  void set_count_primitives(bool on);

  // Draws one frame (waits for it with glFinish) and returns its timing.
  FrameTiming render(const Camera& camera, const Eigen::Ref<const prt::ShLighting>& lighting,
                     const Eigen::Matrix3d& rotation);
  // The framebuffer of the last frame; row 0 at the top.
  Image read_image() const;
  // The same into `into`, reusing its storage (a frame sequence reads into one buffer).
  void read_image(Image& into) const;

  // The per-vertex radiance the mode's vertex stage produces (transform feedback for the GL
  // shading paths), in the mesh's vertex order; for multipass the sum over passes.
  std::vector<Rgb> capture_vertex_radiance(const Camera& camera,
                                           const Eigen::Ref<const prt::ShLighting>& lighting,
                                           const Eigen::Matrix3d& rotation);

  const RenderStats& stats() const;
  Mode mode() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The median-of-frames measurement (docs/ARCHITECTURE.md "Rendering", Timing): `warmup` frames,
// then `frames` frames, each with the environment rotated by `degrees_per_frame` more about `axis`
// (so constants are recomputed every frame, inside the timing), each ended by glFinish. The
// warm-up lasts at least `warmup_ms`: a GPU left idle during set-up (a grouping search) runs
// its first tens of milliseconds of frames at idle clocks, which a median of a few fast frames
// would take for the configuration's speed (docs/BENCHMARKS.md, "On a GPU"). Negative: 300 ms
// on a hardware GPU, none on a software rasteriser (whose clocks are the CPU's).
struct TimingSummary {
  int frames = 0;
  double frame_ms_median = 0, cpu_ms_median = 0, gl_ms_median = 0;
  double fps = 0;  // 1000 / frame_ms_median
};
TimingSummary measure(Renderer& renderer, const Camera& camera,
                      const Eigen::Ref<const prt::ShLighting>& lighting,
                      const Eigen::Matrix3d& start_rotation, const Eigen::Vector3d& axis,
                      double degrees_per_frame, int frames, int warmup, double warmup_ms = -1);

}  // namespace render
