// prt/path_tracer.h: exit radiance under a distant probe by Monte Carlo path tracing, the
// surface light field's data (SLF paper, Sec. 3.1) and the reference images it is judged
// against.
//
// Light transport: the engine's materials exactly as prt::brdf_eval defines them, in the
// frame the PRT bake uses (columns [t b n] of the interpolated per-vertex frame, v toward the
// viewer, s toward the light), occlusion and interreflection through prt::RayScene. At each
// vertex of a path, one sample of the probe (a 2D CDF over its texels, weighted by radiance
// times solid angle) and one of the BRDF (cosine lobe and the specular lobe: Phong's cosine
// power about the mirror direction, Beckmann's half vectors for Cook-Torrance) are combined
// by Veach's power heuristic (Veach & Guibas, "Optimally combining sampling techniques for
// Monte Carlo rendering", 1995); a caller with many views of one point may replace the first
// vertex's probe sample by samples it shares among them (SharedLights, the multi-sample
// model with unequal counts). A BRDF sample that hits the front of a triangle continues
// the path while bounces remain: `bounces` = 1 is one interreflection, as the PRT bake's
// --bounces; 0 is direct light with shadows. Back faces block light and send none, as in the
// bake. A view below the shading normal's tangent plane is taken as the most grazing view
// above it (prt::clamp_to_horizon), raised to kGrazingZ so the BRDF is not zero there.
//
// Deterministic: every path draws its numbers from a counter-based generator keyed by the
// caller's key (texel or pixel, direction, sample) and its own depth, so results do not
// depend on the thread count or on the order paths are traced in.
#pragma once

#include "meshes/mesh.h"
#include "probes/probe.h"
#include "prt/material.h"
#include "prt/ray_scene.h"

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace prt {

// The cosine of the view above the shading tangent plane at which views at or below it are
// evaluated (the BRDF of brdf_eval is zero at v.z = 0).
inline constexpr double kGrazingZ = 1e-3;

struct PathTracerOptions {
  int bounces = 1;           // interreflections, in [0, 16]
  std::uint64_t seed = 1;    // with the caller's keys, fixes every random number
  double ray_offset = 1e-4;  // secondary rays start this times the bounding-box diagonal off
                             // the surface, along the face normal
  // Throws std::invalid_argument naming the option as its CLI flag.
  void validate() const;
};

// The probe's texels as a distribution over directions: texel (x, y) with probability
// proportional to its largest channel (the largest of it and its 8 neighbours, so that every
// direction where a bilinear lookup is non-zero has density) times its solid angle, uniform in
// solid angle inside the texel.
class ProbeSampler {
 public:
  explicit ProbeSampler(const probes::Probe& probe);
  bool empty() const { return total_ <= 0; }  // a black probe: nothing to sample
  // A direction from four uniform numbers in [0, 1), and its density per steradian.
  Eigen::Vector3d sample(double u0, double u1, double u2, double u3, double* pdf) const;
  double pdf(const Eigen::Vector3d& direction) const;
  // The same at lat-long coordinates uv = probes::latlong_uv(direction).
  double pdf_uv(const Eigen::Vector2d& uv) const;

 private:
  int width_ = 0, height_ = 0;
  double total_ = 0;
  std::vector<float> alias_prob_;     // per texel: keep it with this probability,
  std::vector<std::uint32_t> alias_;  // else take this texel (Vose's alias table)
  std::vector<double> texel_pdf_;     // probability / solid angle, per texel
};

// A point on the surface: its position, the unit face normal (for ray offsets and back
// faces) and the shading frame, columns [t b n].
struct SurfacePoint {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d face_normal = Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
};

// Samples of the probe taken once at a surface point and shared by many views of it (the
// surface light field's texel, prt/slf_bake.h): the light rays do not depend on the view, so
// a texel's 512 cells can share a few hundred shadow rays instead of tracing one per path.
// Directions are in the point's shading frame; radiance is the probe's where the direction
// is above the shading plane and unoccluded, zero where not (such samples still count).
struct SharedLights {
  std::vector<Eigen::Vector3d> direction;
  std::vector<double> pdf;  // the probe sampler's density, per steradian
  std::vector<Eigen::Vector3d> radiance;
  std::size_t size() const { return pdf.size(); }
  bool lit(std::size_t j) const { return radiance[j].maxCoeff() > 0; }
};

// One radiance sample to take: leaving `point` toward the world direction `view` (unit),
// with random numbers keyed by `key`; its value is added to slot `slot` of the output.
// With `shared_light_ratio` > 0 the caller estimates the first vertex's light technique
// itself from shared samples (PathTracer::add_shared_light), that many per such query: the
// path then takes no probe sample there and weights its BRDF sample for that many (Veach's
// multi-sample model).
struct ExitQuery {
  SurfacePoint point;
  Eigen::Vector3d view = Eigen::Vector3d::UnitZ();
  std::uint64_t key = 0;
  std::uint32_t slot = 0;
  double shared_light_ratio = 0;
};

class PathTracer {
 public:
  // The mesh needs frames (meshes::compute_frames); the tracer keeps references to the mesh
  // and the probe, which must outlive it. Builds its own ray scene. Throws
  // std::invalid_argument for bad options or an invalid material, RayError if Embree fails.
  PathTracer(const meshes::Mesh& mesh, const probes::Probe& probe, const Material& material,
             const PathTracerOptions& options = {});
  ~PathTracer();
  PathTracer(const PathTracer&) = delete;
  PathTracer& operator=(const PathTracer&) = delete;

  // The point at barycentrics (u, v) of triangle t, p = (1-u-v) p0 + u p1 + v p2, with the
  // interpolated, re-orthonormalised frame (the face's own where the normals cancel).
  SurfacePoint surface_point(std::int32_t triangle, double u, double v) const;

  // Adds one radiance sample per query to out[query.slot] (RGB). Traces all queries' rays
  // together, one stream per kind of ray and depth; call from many threads at once.
  void add_exit_radiance(const std::vector<ExitQuery>& queries, Eigen::Vector3d* out) const;

  // `count` probe samples at `point`, stratified over the sampler's table (sample j draws
  // its first number in [j, j + 1) / count), with one shadow ray each, keyed by `key`.
  SharedLights sample_lights(const SurfacePoint& point, int count, std::uint64_t key) const;

  // The light technique at `point` of shared sample j toward many views: adds to out[i]
  // w f(v_i, s_j) L_j cos_j / p_j for view i (column i of `views`, a world-space unit vector;
  // below-horizon views are clamped as the paths clamp them), weighted by the power
  // heuristic against the BRDF technique for `ratio` light samples per BRDF sample (the
  // ExitQuery's shared_light_ratio). An unlit sample adds nothing. One light against many
  // views at a time, so that the BRDF and its density run on arrays (brdf_eval_batch).
  void add_shared_light(const SurfacePoint& point, const SharedLights& lights, std::size_t j,
                        const Eigen::Matrix3Xd& views, double ratio, Eigen::Vector3d* out) const;

  // The mean of `spp` samples of the radiance leaving `point` toward `view`.
  Eigen::Vector3d exit_radiance(const SurfacePoint& point, const Eigen::Vector3d& view, int spp,
                                std::uint64_t key) const;

  const meshes::Mesh& mesh() const { return mesh_; }
  const probes::Probe& probe() const { return probe_; }
  const PathTracerOptions& options() const { return options_; }
  const RayScene& scene() const { return *scene_; }

 private:
  struct Path;
  void trace(std::vector<Path>& paths, Eigen::Vector3d* out) const;

  const meshes::Mesh& mesh_;
  const probes::Probe& probe_;
  Material material_;
  PathTracerOptions options_;
  std::unique_ptr<RayScene> scene_;
  ProbeSampler sampler_;
  double offset_ = 0;
};

// A pinhole (or any) image: radiance along each camera ray (origins and unit directions,
// 3 x pixels), the mean of `spp` paths per pixel. A ray that misses shows the probe; one that
// hits a back face is black. Parallel over pixels, deterministic for the tracer's seed.
// `progress` (optional) gets pixels done and total, from one thread at a time. Ray i's paths
// are keyed by first_key + i, so an image traced in bands (each band's first_key its first
// ray's index in the whole image) is the image traced at once, to the bit. `hit` (optional,
// one per ray) gets 1 where the ray meets the mesh (either face), else 0: the coverage, from
// the same intersections.
Eigen::Matrix3Xf path_trace_image(
    const PathTracer& tracer, const Eigen::Matrix3Xf& origins, const Eigen::Matrix3Xf& directions,
    int spp, const std::function<void(std::uint64_t, std::uint64_t)>& progress = {},
    std::uint64_t first_key = 0, std::uint8_t* hit = nullptr);

// A counter-based random stream (SplitMix64's finaliser over key and counter, Steele et al.,
// "Fast splittable pseudorandom number generators", 2014): number i of stream `key` is a
// pure function of both, so any sample can be recomputed alone.
struct RandomStream {
  std::uint64_t key = 0, counter = 0;
  double next();  // uniform in [0, 1)
};
std::uint64_t mix_key(std::uint64_t a, std::uint64_t b);

}  // namespace prt
