// prt/bake.h: per-vertex SH transfer by ray tracing (Embree): a shadow pass, then
// interreflection passes. Thesis ch. 3.1.1 (eq. 1-3); conventions in docs/ARCHITECTURE.md.
//
// Method. Every vertex uses the same hemisphere direction set D (prt/sampling.h) expressed
// in its local frame F_p = [t b n], so the SH values Y (n x S) of those directions are
// computed once for the whole mesh; only visibility differs between vertices. With w the
// quadrature weight and O_p the occluded subset:
//  - shadow pass (local frame):  T_p = w sum_{s visible} y(s) y(s)^T
//                                    = w Y Y^T - w Y_O Y_O^T,
//    so a vertex costs work in proportion to its occluded rays (a symmetric rank-k update);
//  - glossy exit transfer:       M_p = B T_p D(F_p^T)   (B: prt/material.h; D: sh_rotation.h)
//    which equals B D(F_p^T) T_p(world) with T_p expressed in the local frame;
//  - diffuse transfer:           t_p = D(F_p) (rho/pi) w sum_{s visible} s_z y(s);
//  - bounce b >= 1: an occluded ray that hits the front of triangle (q0, q1, q2) at
//    barycentrics (u, v) brings r = sum_c beta_c y(F_c^T (-s))^T M_c^{b-1} (glossy) or
//    sum_c beta_c t_c^{b-1} (diffuse), the radiance the hit point sends back along -s;
//    T_p^b = w sum_{s occluded} y(s_local) r, M_p^b = B T_p^b; t_p^b = (rho/pi) w sum s_z r.
//    Back-face hits occlude but bring nothing. The result is sum_b M_p^b.
// Vertices are independent, so the output is bit-identical for any thread count.
//
// Ray origins. Each ray starts on the triangle at p's position (split vertices included)
// whose plane it rises most steeply above: a point a small step from p into that triangle,
// lifted slightly along its normal (the step scales with `ray_offset`). A single offset
// point cannot serve every direction: at a pit, a fold or a thin fin the outside near p is
// a narrow wedge, and the old offset along the summed face normals landed inside the closed
// mesh there. Starting inside the face also keeps rays at a hard edge of split vertices from
// slipping through the crease, and the bounce pass finds its hits from the same points.
// A start point can still be inside the body where a fold takes the vertex itself under a
// neighbouring face. So a vertex whose rays are (nearly) all blocked is probed: if a short
// ray from its start points leaves the body through a back face within 10 offsets, all its
// rays (shadow and bounce) start again from one point just past that exit. Deeper than that
// it is taken to be enclosed: it stays black and is reported.
// Choice and measurements: docs/ARCHITECTURE.md, "Baking (prt/)".
#pragma once

#include "meshes/mesh.h"
#include "prt/material.h"
#include "prt/transfer.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace prt {

struct BakeProgress {
  int pass = 0;                       // 0 = shadow pass, b = bounce b
  int passes = 1;                     // 1 + bounces
  std::uint64_t done = 0, total = 0;  // vertices finished in this pass
};

struct BakeOptions {
  TransferKind kind = TransferKind::kGlossy;
  int order = 6;
  int samples = 1024;  // hemisphere directions per vertex
  int bounces = 1;
  std::uint64_t seed = 1;
  Material material;
  // Glossy: how B's view side represents exit radiance (prt/view_fit.h); renderable fits only.
  ViewFit view_fit = kDefaultViewFit;
  double ray_offset = 1e-4;  // times the bounding-box diagonal; origins step a tenth of it
  // Glossy only: use this n x n matrix for every channel instead of the material's BRDF
  // matrix (a measured BRDF projected elsewhere; tests pass the identity to read T_p).
  // The file still records `material`.
  std::optional<Eigen::MatrixXd> brdf_override;
  // Called from worker threads, never concurrently with itself, at most every ~50 ms.
  std::function<void(const BakeProgress&)> progress;
};

// Throws std::invalid_argument naming the option (as its CLI flag) when out of range.
void validate(const BakeOptions& options);

struct BakeEstimate {
  std::uint64_t bytes = 0;  // peak memory of the bake's buffers
  std::uint64_t rays = 0;   // shadow-pass rays (bounces re-trace only the occluded ones)
  std::uint64_t output_bytes = 0;
  // Wall time from per-thread rates measured on the bunny (glossy order 6: ~4 M shadow
  // rays/s per thread, a bounce costing ~1.2x the shadow pass); a guide, not a promise.
  double seconds = 0;
};
BakeEstimate estimate_bake(const meshes::Mesh& mesh, const BakeOptions& options);

// Bytes of memory available now (MemAvailable in /proc/meminfo), 0 if unknown.
std::uint64_t available_memory();

// A vertex is nearly occluded when less than this share of its shadow rays escapes.
inline constexpr double kNearlyOccluded = 0.01;

struct BakeStats {
  double seconds_shadow = 0, seconds_bounces = 0, seconds_brdf = 0, seconds_total = 0;
  std::uint64_t rays_shadow = 0, rays_bounce = 0;
  double occluded_fraction = 0;
  // Rows of previous passes that a streaming bake's bounces read into memory (their hits'
  // corners, a bounded cache's misses); 0 for an in-memory bake, which holds every pass.
  std::uint64_t rows_gathered = 0;
  // Nearly occluded vertices, ascending. A sound surface rarely has any: they render black,
  // and point at enclosed or broken geometry (or rays that start inside the surface).
  std::vector<std::uint32_t> occluded_vertices;
  // Nearly occluded vertices whose start points were found just inside a closed surface
  // (a back face within 10 offsets) and whose rays were traced again from just past it,
  // ascending. Those still nearly occluded afterwards are in occluded_vertices too.
  std::vector<std::uint32_t> moved_origins;
};

// The mesh must have frames (meshes::compute_frames). Throws std::invalid_argument for bad
// options and RayError if Embree fails.
TransferSet bake(const meshes::Mesh& mesh, const BakeOptions& options, BakeStats* stats = nullptr);

// The same bake written straight to a .prtx at `path`, `block_vertices` vertices at a time
// (0: default_block_vertices), so memory holds a block, the mesh and the ray scene but never
// the whole payload. The file is byte for byte write_transfer(path, bake(mesh, options)).
// With bounces, the shadow pass and its front hits go to scratch files beside `path` and
// each bounce reads the rows of the previous pass that its hits reach into a cache of
// kGatherBlocks blocks (docs/ARCHITECTURE.md, "Scale").
// Atomic: nothing is left at `path` (or beside it) unless the bake completes. Returns the
// header fields (data empty).
TransferSet bake_to_file(const meshes::Mesh& mesh, const BakeOptions& options,
                         const std::filesystem::path& path, std::uint64_t block_vertices = 0,
                         BakeStats* stats = nullptr);

// Shard `index` of `count` of that bake: its vertex range (prt/transfer_shard.h) into a
// shard file for prt::merge_shards. Bounces need every vertex's previous pass, so a shard
// bake refuses bounces > 0 (std::invalid_argument naming --shard).
TransferSet bake_shard_to_file(const meshes::Mesh& mesh, const BakeOptions& options,
                               const std::filesystem::path& path, std::uint32_t index,
                               std::uint32_t count, std::uint64_t block_vertices = 0,
                               BakeStats* stats = nullptr);

// Rank `index` of `count` processes that bake one file at `path` together (mpirun): each
// writes the rows of its shard range (prt::shard_range) straight into the partial file that
// prt::TransferSliceWriter keeps beside `path`; once every rank has returned, one calls
// prt::commit_transfer_slices(path, shape), and the file is the one-process bake's bytes.
// With bounces, each rank computes every pass for its range of the spatial order, writes the
// pass into `path`.pass0 or .pass1 (alternating; every rank must see the same file) and calls
// `barrier`, which returns once every rank has called it; pass b + 1 then reads pass b. The
// caller removes the pass files after the last barrier. docs/ARCHITECTURE.md, "Scale".
TransferSet bake_rank(const meshes::Mesh& mesh, const BakeOptions& options,
                      const std::filesystem::path& path, std::uint32_t index, std::uint32_t count,
                      const std::function<void()>& barrier, std::uint64_t block_vertices = 0,
                      BakeStats* stats = nullptr);

// Vertices per block holding about 16 MiB of transfer (a multiple of 64, at least 64).
std::uint64_t default_block_vertices(std::size_t floats_per_vertex);

// The bounces' cache of previous-pass rows holds this many blocks' worth of rows.
inline constexpr std::uint64_t kGatherBlocks = 16;

}  // namespace prt
