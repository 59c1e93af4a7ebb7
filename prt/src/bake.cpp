// The baker: shadow pass and interreflection passes (thesis ch. 3.1.1, eq. 1-3; Sloan,
// Kautz & Snyder 2002, section 5). See prt/bake.h for the formulation this file follows.
#include "prt/bake.h"

#include "bake_engine.h"
#include "corner_gather.h"
#include "meshes/weld.h"

#include "prt/ray_scene.h"
#include "prt/sampling.h"
#include "prt/sh.h"
#include "prt/sh_rotation.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <mutex>
#include <numbers>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>

namespace prt {
namespace {

using Clock = std::chrono::steady_clock;
using MatF = Eigen::MatrixXf;  // column-major
using RowMatF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

using detail::HitBlock;
using detail::HitRecord;
using detail::kChunk;
using detail::VertexList;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// What every vertex shares: the local direction set and its SH values.
struct Setup {
  int order = 0, n = 0, samples = 0;
  float weight = 0;
  Eigen::Matrix3Xf directions;        // local frame, z = normal
  MatF y;                             // n x S, column k = y(direction k)
  MatF gram;                          // w Y Y^T: the unoccluded shadow transfer
  Eigen::VectorXf cosine_projection;  // w sum_k z_k y_k: the unoccluded diffuse transfer
  std::vector<MatF> brdf;             // per channel, n x n (glossy only)
  Eigen::Vector3f rho_over_pi;        // diffuse albedo / pi per channel
};

Eigen::Matrix3f frame_of(const meshes::Mesh& mesh, std::size_t p) {
  Eigen::Matrix3f f;
  f.col(0) = mesh.tangents[p];
  f.col(1) = mesh.bitangents[p];
  f.col(2) = mesh.normals[p];
  return f;
}

// M <- M D (D block diagonal, given as a rotation's bands), i.e. each band's columns.
// `bands` and `scratch` are caller-owned so a vertex allocates nothing.
void multiply_bands_right(MatF& m, const ShRotation& d, std::vector<MatF>& bands, MatF& scratch) {
  scratch = m;
  for (int l = 0; l < d.order(); ++l) {
    const int size = 2 * l + 1;
    bands[l] = d.band(l).cast<float>();
    m.middleCols(l * l, size).noalias() = scratch.middleCols(l * l, size) * bands[l];
  }
}

// Calls the user's progress callback from workers, serialised and rate-limited.
class ProgressReporter {
 public:
  ProgressReporter(const std::function<void(const BakeProgress&)>& fn, int passes,
                   std::uint64_t total)
      : fn_(fn), passes_(passes), total_(total) {}
  void start_pass(int pass) {
    pass_ = pass;
    done_ = 0;
    report(true);
  }
  void add(std::uint64_t vertices) {
    done_ += vertices;
    report(false);
  }
  void finish_pass() { report(true); }

 private:
  void report(bool force) {
    if (!fn_) return;
    std::unique_lock<std::mutex> lock(mutex_, std::defer_lock);
    if (force) {
      lock.lock();
    } else if (!lock.try_lock()) {
      return;
    }
    const auto now = Clock::now();
    if (!force && now - last_ < std::chrono::milliseconds(50)) return;
    last_ = now;
    fn_(BakeProgress{pass_, passes_, std::min<std::uint64_t>(done_.load(), total_), total_});
  }
  const std::function<void(const BakeProgress&)>& fn_;
  int passes_;
  std::uint64_t total_;
  int pass_ = 0;
  std::atomic<std::uint64_t> done_{0};
  std::mutex mutex_;
  Clock::time_point last_{};
};

// Where each vertex's rays start (prt/bake.h, "Ray origins"; docs/ARCHITECTURE.md, "Baking
// (prt/)"). Every triangle at a vertex's position, split vertices included, offers a start
// point: a step from the corner into the triangle, toward its centroid, lifted a tenth of
// that step along its normal. A ray starts from the face whose plane it rises most steeply
// above. One shared origin cannot be outside everywhere: at a pit or a crease the outside
// near the vertex is a narrow wedge, and a fixed direction can miss it.
struct OriginFaces {
  std::vector<std::uint32_t> group;  // vertex -> position group
  std::vector<std::uint32_t> first;  // group g's entries are [first[g], first[g + 1])
  Eigen::Matrix3Xf normals;          // unit face normal of each entry
  Eigen::Matrix3Xf steps;            // corner to start point, in world units
};

// Start points sit kStep x offset into their face and kLift of that above it. The lift keeps
// them ~50 float ulps off their own face's plane at the default offset (1e-4 of the
// diagonal), so Embree cannot report the face itself, yet small against the step, so a
// start point stays inside wedges down to ~10 degrees between faces. The step is a tenth of
// the offset because the bunny's pits fold at that scale: their visibility converges to a
// brute-force count from a point just outside as the step shrinks (docs/ARCHITECTURE.md).
constexpr float kStep = 0.1f;
constexpr float kLift = 0.1f;

// A nearly occluded vertex whose start points lie just inside a closed surface (a fold can
// take a vertex under its neighbouring face) starts its rays again from just past the exit.
// "Just": the first hit along a probe is a back face within kEscape x offset. The folds
// measured so far are 0.6 and 1.5 offsets deep (bunny, horse); the nearest exit from
// genuinely enclosed parts (glmark2's cat) is 28 offsets away, so those stay black and
// flagged (docs/ARCHITECTURE.md).
constexpr float kEscape = 10.f;

OriginFaces origin_faces(const meshes::Mesh& mesh, float offset) {
  OriginFaces f;
  meshes::PositionGroups groups = meshes::group_equal_positions(mesh.positions);
  f.group = std::move(groups.group);
  const std::size_t group_count = groups.count();
  // Zero-area faces have no plane to start above; they are left out.
  auto unit_normal = [&](const meshes::Triangle& t) {
    return (mesh.positions[t[1]] - mesh.positions[t[0]])
        .cross(mesh.positions[t[2]] - mesh.positions[t[0]])
        .normalized()
        .eval();
  };
  f.first.assign(group_count + 1, 0);
  for (const meshes::Triangle& t : mesh.triangles) {
    if (!unit_normal(t).allFinite()) continue;
    for (int c = 0; c < 3; ++c) ++f.first[f.group[t[c]] + 1];
  }
  for (std::size_t g = 0; g < group_count; ++g) f.first[g + 1] += f.first[g];
  std::vector<std::uint32_t> fill(f.first.begin(), f.first.end() - 1);
  f.normals.resize(3, f.first.back());
  f.steps.resize(3, f.first.back());
  for (const meshes::Triangle& t : mesh.triangles) {
    const meshes::Vec3 n = unit_normal(t);
    if (!n.allFinite()) continue;
    const meshes::Vec3 centroid =
        (mesh.positions[t[0]] + mesh.positions[t[1]] + mesh.positions[t[2]]) / 3.f;
    for (int c = 0; c < 3; ++c) {
      const meshes::Vec3 inward = centroid - mesh.positions[t[c]];
      // Half the way to the centroid at most, so the start point stays on a small face.
      const float step = std::min(kStep * offset, 0.5f * inward.norm());
      const std::uint32_t e = fill[f.group[t[c]]]++;
      f.normals.col(e) = n;
      f.steps.col(e) = step * (inward.normalized() + kLift * n);
    }
  }
  return f;
}

Setup make_setup(const BakeOptions& o, int channels, double* brdf_seconds) {
  Setup s;
  s.order = o.order;
  s.n = sh_count(o.order);
  s.samples = o.samples;
  const DirectionSet set = hemisphere_directions(o.samples, o.seed);
  s.weight = static_cast<float>(set.weight);
  s.directions = set.directions.cast<float>();
  ShBatchF batch;
  sh_eval_batch(o.order, s.directions, batch);
  s.y = batch;  // to column-major: gathering a direction's values copies one column
  s.gram = s.weight * (s.y * s.y.transpose());
  s.cosine_projection = s.weight * (s.y * s.directions.row(2).transpose());
  s.rho_over_pi = o.material.albedo / std::numbers::pi_v<float>;
  if (o.kind == TransferKind::kGlossy) {
    const auto start = Clock::now();
    for (int c = 0; c < channels; ++c) {
      s.brdf.push_back(
          o.brdf_override
              ? o.brdf_override->cast<float>().eval()
              : brdf_matrix(o.material, o.order, c, {}, o.view_fit).cast<float>().eval());
    }
    *brdf_seconds = seconds_since(start);
  }
  return s;
}

}  // namespace

void validate(const BakeOptions& o) {
  check_order(o.order, "--order");
  if (o.samples < 1 || o.samples > 65536) {
    throw std::invalid_argument("--samples must be in [1, 65536], got " +
                                std::to_string(o.samples));
  }
  if (o.bounces < 0 || o.bounces > 16) {
    throw std::invalid_argument("--bounces must be in [0, 16], got " + std::to_string(o.bounces));
  }
  if (!(o.ray_offset > 0.0 && o.ray_offset <= 0.01)) {
    throw std::invalid_argument(
        "--ray-offset must be in (0, 0.01] (a fraction of the bounding "
        "box diagonal), got " +
        std::to_string(o.ray_offset));
  }
  o.material.validate();
  if (!view_fit_renderable(o.view_fit)) {
    throw std::invalid_argument(std::string("--view-fit ") + view_fit_name(o.view_fit) +
                                " is for the benchmarks only; bake with least-squares, even or "
                                "hemisphere");
  }
  const int n = sh_count(o.order);
  if (o.brdf_override && (o.brdf_override->rows() != n || o.brdf_override->cols() != n)) {
    throw std::invalid_argument("BRDF matrix override must be " + std::to_string(n) + " x " +
                                std::to_string(n) + " for order " + std::to_string(o.order));
  }
}

std::uint64_t available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t value = 0;
  std::string unit;
  while (in >> key >> value >> unit) {
    if (key == "MemAvailable:") return value * 1024;
  }
  return 0;
}

BakeEstimate estimate_bake(const meshes::Mesh& mesh, const BakeOptions& o) {
  TransferSet shape;
  shape.kind = o.kind;
  shape.order = o.order;
  shape.channels = o.material.channels();
  const std::uint64_t v = mesh.vertex_count();
  BakeEstimate e;
  e.output_bytes = v * shape.floats_per_vertex() * sizeof(float);
  // Output, plus the previous and current bounce; hit records assume every ray is occluded.
  const int buffers = 1 + (o.bounces > 0 ? 1 : 0) + (o.bounces > 1 ? 1 : 0);
  e.bytes = e.output_bytes * buffers +
            (o.bounces > 0 ? v * std::uint64_t(o.samples) * sizeof(HitRecord) : 0);
  e.rays = v * std::uint64_t(o.samples);
  const double threads = std::max(1, tbb::this_task_arena::max_concurrency());
  const double n2 = double(sh_count(o.order)) * sh_count(o.order);
  const double per_ray =
      1.0 / 4e6 * (o.kind == TransferKind::kGlossy ? std::max(1.0, n2 / 1296) : 1.0);
  e.seconds = double(e.rays) * per_ray * (1.0 + 1.2 * o.bounces) * shape.channels / threads;
  return e;
}

namespace {

// What both passes read: the inputs, the shared direction set and the ray scene.
struct BakeContext {
  BakeContext(const meshes::Mesh& m, const BakeOptions& o, const Setup& s, const RayScene* r)
      : mesh(m), options(o), setup(s), scene(r) {}
  const meshes::Mesh& mesh;
  const BakeOptions& options;
  const Setup& setup;
  const RayScene* scene;  // null once tracing ends (BakeEngine::end_tracing)
  int channels = 0;
  bool glossy = false;
  float offset = 0;  // ray-origin offset in world units
  OriginFaces faces;
  std::uint64_t vertex_count = 0;
  std::size_t per_vertex = 0, per_channel = 0;  // floats of the output layout
};

// Per-thread scratch of the shadow pass, allocated once per thread and reused for every vertex.
struct ShadowScratch {
  ShadowScratch(int order, int n, int samples) : rotation(order, Eigen::Matrix3d::Identity()) {
    world.resize(3, samples);
    occluded.resize(samples);
    occluded_index.resize(samples);
    y_occluded.resize(n, samples);
    transfer.resize(n, n);
    scratch.resize(n, n);
    diffuse_local.resize(n);
    diffuse_world.resize(n);
    for (int l = 0; l < order; ++l) bands.emplace_back(2 * l + 1, 2 * l + 1);
    occluded_world.resize(3, samples);
    origins.resize(3, samples);
    occluded_origins.resize(3, samples);
    hits.resize(samples);
  }
  Eigen::Matrix3Xf world;
  std::vector<std::uint8_t> occluded;
  std::vector<int> occluded_index;
  MatF y_occluded, transfer, scratch;
  Eigen::VectorXf diffuse_local;
  Eigen::VectorXd diffuse_world;
  ShRotation rotation;  // D of the current vertex's frame, rebuilt in place
  std::vector<MatF> bands;
  Eigen::Matrix3Xf occluded_world;
  Eigen::Matrix3Xf origins, occluded_origins;  // per ray, for world and occluded_world
  std::vector<RayHit> hits;
  std::uint64_t rays_shadow = 0, rays_bounce = 0, occluded_count = 0;
};
using ShadowPool = tbb::enumerable_thread_specific<ShadowScratch>;

// Start points of p's rays (s.world) into s.origins: each on the face at p's position whose
// plane the ray rises most steeply above. A vertex on no face starts above itself.
void ray_origins(const BakeContext& ctx, ShadowScratch& s, std::uint64_t p) {
  const OriginFaces& f = ctx.faces;
  const std::uint32_t g = f.group[p], begin = f.first[g], end = f.first[g + 1];
  const meshes::Vec3& at = ctx.mesh.positions[p];
  if (begin == end) {
    s.origins.colwise() = at + ctx.offset * ctx.mesh.normals[p];
    return;
  }
  for (Eigen::Index k = 0; k < s.world.cols(); ++k) {
    const Eigen::Vector3f d = s.world.col(k);
    std::uint32_t best = begin;
    float best_rise = f.normals.col(begin).dot(d);
    for (std::uint32_t e = begin + 1; e < end; ++e) {
      const float rise = f.normals.col(e).dot(d);
      if (rise > best_rise) best_rise = rise, best = e;
    }
    s.origins.col(k) = at + f.steps.col(best);
  }
}

// Traces p's shadow rays (s.world) from s.origins; leaves the occluded directions in
// s.occluded_index and their SH values in s.y_occluded, and returns how many there are.
int trace_from_origins(const BakeContext& ctx, ShadowScratch& s) {
  const Setup& setup = ctx.setup;
  ctx.scene->occluded_from(s.origins, s.world, 0.f, s.occluded.data());
  int k = 0;
  for (int d = 0; d < setup.samples; ++d) {
    if (!s.occluded[d]) continue;
    s.occluded_index[k] = d;
    s.y_occluded.col(k) = setup.y.col(d);
    ++k;
  }
  s.rays_shadow += setup.samples;
  return k;
}

int trace_shadow_rays(const BakeContext& ctx, ShadowScratch& s, std::uint64_t p,
                      const Eigen::Matrix3f& frame) {
  s.world.noalias() = frame * ctx.setup.directions;
  ray_origins(ctx, s, p);
  return trace_from_origins(ctx, s);
}

// Where p's rays should start instead when its start points are just inside a closed
// surface: probes from each start point, along p's normal and the start face's normal, look
// for a first hit on a back face (the ray leaves the body) closer than kEscape x offset. The
// nearest such exit wins, and the new origin sits that exit's lift above it, on its outer
// side. None when every probe first meets a front face, nothing, or a distant back face.
std::optional<Eigen::Vector3f> escape_origin(const BakeContext& ctx, std::uint64_t p) {
  const OriginFaces& f = ctx.faces;
  const std::uint32_t g = f.group[p], begin = f.first[g], end = f.first[g + 1];
  const meshes::Mesh& mesh = ctx.mesh;
  const meshes::Vec3& at = mesh.positions[p];
  const float bound = kEscape * ctx.offset, lift = kLift * kStep * ctx.offset;
  std::optional<Eigen::Vector3f> best;
  float best_t = bound;
  Eigen::Matrix3Xf probes(3, 2);
  RayHit hits[2];
  for (std::uint32_t e = begin; e < end; ++e) {
    const Eigen::Vector3f start = at + f.steps.col(e);
    probes.col(0) = mesh.normals[p];
    probes.col(1) = f.normals.col(e);
    ctx.scene->intersect(start, probes, 0.f, hits);
    for (int j = 0; j < 2; ++j) {
      const RayHit& h = hits[j];
      if (h.triangle < 0 || !(h.t < best_t)) continue;
      const meshes::Triangle& tri = mesh.triangles[h.triangle];
      const Eigen::Vector3f n = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                                    .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]])
                                    .normalized();
      if (!(n.dot(probes.col(j)) > 0.f)) continue;
      best_t = h.t;
      best = (start + h.t * probes.col(j) + lift * n).eval();
    }
  }
  return best;
}

void glossy_shadow_transfer(const BakeContext& ctx, ShadowScratch& s, int k,
                            const Eigen::Matrix3f& frame, float* dst) {
  const Setup& setup = ctx.setup;
  const int n = setup.n;
  // T = w Y Y^T - w Y_O Y_O^T as a symmetric rank-k update of the lower triangle.
  s.transfer = setup.gram;
  if (k > 0) {
    s.transfer.selfadjointView<Eigen::Lower>().rankUpdate(s.y_occluded.leftCols(k), -setup.weight);
  }
  s.transfer.triangularView<Eigen::StrictlyUpper>() = s.transfer.transpose();
  s.rotation.set(frame.transpose().cast<double>());  // D(F^T): world to local
  multiply_bands_right(s.transfer, s.rotation, s.bands, s.scratch);
  for (int c = 0; c < ctx.channels; ++c) {
    Eigen::Map<RowMatF> m(dst + c * ctx.per_channel, n, n);
    m.noalias() = setup.brdf[c] * s.transfer;
  }
}

void diffuse_shadow_transfer(const BakeContext& ctx, ShadowScratch& s, int k,
                             const Eigen::Matrix3f& frame, float* dst) {
  const Setup& setup = ctx.setup;
  Eigen::VectorXf& t = s.diffuse_local;
  t = setup.cosine_projection;
  for (int j = 0; j < k; ++j) {
    t -= (setup.weight * setup.directions(2, s.occluded_index[j])) *
         setup.y.col(s.occluded_index[j]);
  }
  // World frame: t_world = D(F) t_local.
  s.rotation.set(frame.cast<double>());
  s.rotation.apply(t.cast<double>(), s.diffuse_world);
  for (int c = 0; c < ctx.channels; ++c) {
    Eigen::Map<Eigen::VectorXf>(dst + c * ctx.per_channel, setup.n) =
        setup.rho_over_pi[c] * s.diffuse_world.cast<float>();
  }
}

// Closest hits of p's k occluded rays, kept for every bounce; back faces send no light.
void record_front_hits(const BakeContext& ctx, ShadowScratch& s, int k, HitBlock& block) {
  const meshes::Mesh& mesh = ctx.mesh;
  for (int j = 0; j < k; ++j) {
    s.occluded_world.col(j) = s.world.col(s.occluded_index[j]);
    s.occluded_origins.col(j) = s.origins.col(s.occluded_index[j]);
  }
  ctx.scene->intersect_from(s.occluded_origins.leftCols(k), s.occluded_world.leftCols(k), 0.f,
                            s.hits.data());
  s.rays_bounce += k;
  for (int j = 0; j < k; ++j) {
    const RayHit& h = s.hits[j];
    if (h.triangle < 0) continue;
    const meshes::Triangle& tri = mesh.triangles[h.triangle];
    const Eigen::Vector3f face = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                                     .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]]);
    if (face.dot(s.occluded_world.col(j)) >= 0.f) continue;
    block.records.push_back(HitRecord{std::uint16_t(s.occluded_index[j]), h.triangle, h.u, h.v});
  }
  block.offsets.push_back(std::uint32_t(block.records.size()));
}

// Per-vertex outcome of the shadow pass.
enum VertexFlag : std::uint8_t { kNearly = 1, kMoved = 2 };

// Direct light: the shadow-pass transfer of `vertices` into dst (row i for vertices[i]),
// and (with bounces) the front hits each vertex's occluded rays find, per kChunk of them. flags[p]
// has kNearly where p sees less than kNearlyOccluded of its rays escape, and kMoved where its
// origin was moved out of the body.
void shadow_range(const BakeContext& ctx, ShadowPool& pool, VertexList vertices, float* dst,
                  std::vector<HitBlock>* hit_blocks, std::vector<std::uint8_t>& flags,
                  ProgressReporter& progress) {
  const double visible_floor = kNearlyOccluded * ctx.setup.samples;
  const std::uint64_t count = vertices.size();
  const std::uint64_t chunks = (count + kChunk - 1) / kChunk;
  if (hit_blocks) hit_blocks->assign(chunks, HitBlock{});
  tbb::parallel_for(std::uint64_t(0), chunks, [&](std::uint64_t chunk) {
    ShadowScratch& s = pool.local();
    const std::uint64_t begin = chunk * kChunk, end = std::min(count, begin + kChunk);
    HitBlock* block = hit_blocks ? &(*hit_blocks)[chunk] : nullptr;
    if (block) block->offsets.assign(1, 0);
    for (std::uint64_t i = begin; i < end; ++i) {
      const std::uint32_t p = vertices[i];
      const Eigen::Matrix3f frame = frame_of(ctx.mesh, p);
      int k = trace_shadow_rays(ctx, s, p, frame);
      auto dark = [&] { return double(ctx.setup.samples - k) < visible_floor; };
      std::uint8_t flag = 0;
      if (dark()) {
        if (const std::optional<Eigen::Vector3f> origin = escape_origin(ctx, p)) {
          // One point serves every ray: past the exit, the local surface is that one face.
          s.origins.colwise() = *origin;
          k = trace_from_origins(ctx, s);
          flag |= kMoved;
        }
        if (dark()) flag |= kNearly;
      }
      flags[p] = flag;
      s.occluded_count += k;
      float* out = dst + i * ctx.per_vertex;
      if (ctx.glossy) {
        glossy_shadow_transfer(ctx, s, k, frame, out);
      } else {
        diffuse_shadow_transfer(ctx, s, k, frame, out);
      }
      if (block) record_front_hits(ctx, s, k, *block);
    }
    progress.add(end - begin);
  });
}

// Per-thread scratch of the interreflection passes.
struct BounceScratch {
  BounceScratch(int n, int samples) {
    corner_dirs.resize(3, 3 * samples);
    y_hit.resize(n, samples);
    rows.resize(samples, n);
    transfer.resize(n, n);
  }
  Eigen::Matrix3Xf corner_dirs;
  ShBatchF corner_batch;
  MatF corner_y;
  MatF y_hit, transfer;
  RowMatF rows;  // row h is updated per hit: keep it contiguous
};
using BouncePool = tbb::enumerable_thread_specific<BounceScratch>;

// A vertex's frame, stored with its row of the previous pass: a hit's corners are read
// together with their transfer.
struct CornerFrame {
  Eigen::Vector3f tangent, bitangent, normal;
};

// The previous bounce's transfer of the vertices a bounce reads, with its layout.
struct BounceSource {
  const float* previous;        // M^{b-1}: the whole pass, or the rows gathered (slot_of)
  const std::uint32_t* row_of;  // vertex q is row row_of[q] of the pass; null: row q
  const CornerFrame* frames;    // by row of the pass
  std::size_t per_vertex, per_channel;
  const std::uint32_t* slot_of = nullptr;  // vertex q is row slot_of[q] of previous
  std::size_t row_index(std::uint32_t q) const { return row_of ? row_of[q] : q; }
  const float* row(std::uint32_t q) const {
    return previous + (slot_of ? slot_of[q] : row_index(q)) * per_vertex;
  }
};

// Glossy corners emit toward p: the directions back to p seen from each hit triangle's
// corners, in the corners' frames, and their SH values.
void corner_view_directions(const BakeContext& ctx, BounceScratch& s, const BounceSource& src,
                            const HitRecord* hits, int count, const Eigen::Matrix3f& frame) {
  for (int h = 0; h < count; ++h) {
    const Eigen::Vector3f back = -(frame * ctx.setup.directions.col(hits[h].direction));
    const meshes::Triangle& tri = ctx.mesh.triangles[hits[h].triangle];
    for (int c = 0; c < 3; ++c) {
      const CornerFrame& f = src.frames[src.row_index(tri[c])];
      // A corner whose normal leans away from p sees p below its own horizon: it sends what
      // it sends toward its horizon (prt/view_fit.h), not the fit's extension below it.
      s.corner_dirs.col(3 * h + c) = clamp_to_horizon(
          Eigen::Vector3f(f.tangent.dot(back), f.bitangent.dot(back), f.normal.dot(back)));
    }
  }
  sh_eval_batch(ctx.options.order, s.corner_dirs.leftCols(3 * count), s.corner_batch);
  s.corner_y = s.corner_batch;  // column-major: each corner's values contiguous
}

// A multiply-add rounded as Eigen's packet code rounds it: fused where the target has FMA.
inline float multiply_add(float a, float b, float c) {
#if defined(__FMA__)
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

// out += sum_c beta[c] y_c^T M_c over a hit triangle's three corners (M_c: n x n, row-major;
// y_c: n contiguous values, the three one after another), each element rounded exactly as
// Eigen's matrix-vector product rounds `out.noalias() += beta[c] * (y_c^T * M_c)` for c = 0, 1,
// 2 in turn: a fused chain over the rows of M_c from zero, then one multiply-add onto out.
// Eigen's kernel runs one corner at a time, so each output element waits on its own chain of
// n dependent multiply-adds; here the three corners' chains run side by side, with the
// accumulators in registers when n is known at compile time (N > 0).
template <int N>
void interpolate_corners(const float* const corners[3], const float* y, const float beta[3],
                         int n_runtime, float* out) {
  const int n = N > 0 ? N : n_runtime;
  constexpr int kMax = N > 0 ? N : kMaxOrder * kMaxOrder;
  float g[3][kMax];
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < n; ++i) g[c][i] = 0.f;
  for (int j = 0; j < n; ++j) {
    for (int c = 0; c < 3; ++c) {
      const float x = y[c * n + j];
      const float* m = corners[c] + std::size_t(j) * n;
      for (int i = 0; i < n; ++i) g[c][i] = multiply_add(m[i], x, g[c][i]);
    }
  }
  for (int i = 0; i < n; ++i) {
    float r = out[i];
    for (int c = 0; c < 3; ++c) r = multiply_add(g[c][i], beta[c], r);
    out[i] = r;
  }
}

// The same through Eigen's product, one corner at a time: for the widths whose rounding the
// kernel does not reproduce.
void interpolate_corners_eigen(const float* const corners[3], const float* y, const float beta[3],
                               int n, float* out) {
  Eigen::Map<Eigen::RowVectorXf> row(out, n);
  for (int c = 0; c < 3; ++c) {
    row.noalias() += beta[c] * (Eigen::Map<const Eigen::VectorXf>(y + c * n, n).transpose() *
                                Eigen::Map<const RowMatF>(corners[c], n, n));
  }
}

using InterpolateCorners = void (*)(const float* const[3], const float*, const float[3], int,
                                    float*);

// The kernel for n coefficients, unrolled for the orders a glossy bake is usually run at.
// Eigen's own product where it would round differently: it finishes a row count that is not
// a multiple of 4 (odd orders) with scalar code, which this translation unit does not
// contract into fused multiply-adds.
InterpolateCorners corner_interpolation(int n) {
  switch (n) {
    case 16:
      return interpolate_corners<16>;
    case 36:
      return interpolate_corners<36>;
    case 64:
      return interpolate_corners<64>;
    default:
      return n % 4 == 0 ? interpolate_corners<0> : interpolate_corners_eigen;
  }
}

// rows.row(h): the radiance hit h sends toward p in channel ch, as a function of lighting,
// interpolated from its triangle's corners.
void hit_radiance_rows(const BakeContext& ctx, BounceScratch& s, const BounceSource& src,
                       const HitRecord* hits, int count, int ch) {
  const int n = ctx.setup.n;
  s.rows.topRows(count).setZero();
  const InterpolateCorners interpolate = corner_interpolation(n);
  for (int h = 0; h < count; ++h) {
    const meshes::Triangle& tri = ctx.mesh.triangles[hits[h].triangle];
    const float beta[3] = {1.f - hits[h].u - hits[h].v, hits[h].u, hits[h].v};
    const float* corners[3];
    for (int c = 0; c < 3; ++c) corners[c] = src.row(tri[c]) + ch * src.per_channel;
    if (ctx.glossy) {
      interpolate(corners, s.corner_y.col(3 * h).data(), beta, n, s.rows.row(h).data());
    } else {
      for (int c = 0; c < 3; ++c)
        s.rows.row(h) += beta[c] * Eigen::Map<const Eigen::RowVectorXf>(corners[c], n);
    }
  }
}

// One vertex of bounce b: its transfer from the light its front hits send back.
void bounce_vertex(const BakeContext& ctx, BounceScratch& s, const BounceSource& src,
                   const HitRecord* hits, int count, std::uint64_t p, float* dst) {
  const Setup& setup = ctx.setup;
  const int n = setup.n;
  if (count == 0) {
    std::fill(dst, dst + src.per_vertex, 0.f);
    return;
  }
  if (ctx.glossy) corner_view_directions(ctx, s, src, hits, count, frame_of(ctx.mesh, p));
  for (int h = 0; h < count; ++h) s.y_hit.col(h) = setup.y.col(hits[h].direction);
  for (int ch = 0; ch < ctx.channels; ++ch) {
    hit_radiance_rows(ctx, s, src, hits, count, ch);
    float* out_ch = dst + ch * src.per_channel;
    if (ctx.glossy) {
      s.transfer.noalias() = setup.weight * (s.y_hit.leftCols(count) * s.rows.topRows(count));
      Eigen::Map<RowMatF>(out_ch, n, n).noalias() = setup.brdf[ch] * s.transfer;
    } else {
      Eigen::Map<Eigen::RowVectorXf> t(out_ch, n);
      t.setZero();
      for (int h = 0; h < count; ++h) t += setup.directions(2, hits[h].direction) * s.rows.row(h);
      t *= setup.weight * setup.rho_over_pi[ch];
    }
  }
}

// One interreflection pass over the vertices [first, last) of `vertices`: their bounce-b
// transfer, into dst (row i for vertices[i]), from bounce b - 1's of the vertices their hits
// reach (src). Work is split at chunk boundaries.
void bounce_range(const BakeContext& ctx, BouncePool& pool, const std::vector<HitBlock>& hit_blocks,
                  const BounceSource& src, VertexList vertices, std::uint64_t first,
                  std::uint64_t last, float* dst, ProgressReporter& progress) {
  if (first >= last) return;
  tbb::parallel_for(first / kChunk, (last - 1) / kChunk + 1, [&](std::uint64_t chunk) {
    BounceScratch& s = pool.local();
    const HitBlock& block = hit_blocks[chunk];
    const std::uint64_t base = chunk * kChunk;
    const std::uint64_t begin = std::max(first, base), end = std::min(last, base + kChunk);
    for (std::uint64_t i = begin; i < end; ++i) {
      const std::uint32_t at = block.offsets[i - base];
      const int hits = int(block.offsets[i - base + 1] - at);
      bounce_vertex(ctx, s, src, block.records.data() + at, hits, vertices[i],
                    dst + i * src.per_vertex);
    }
    progress.add(end - begin);
  });
}

}  // namespace

namespace detail {

struct BakeEngine::State {
  State(const meshes::Mesh& mesh, const BakeOptions& o, BakeStats& st)
      : stats(st),
        setup(make_setup(o, o.material.channels(), &st.seconds_brdf)),
        scene(std::make_unique<RayScene>(mesh)),
        ctx(mesh, o, setup, scene.get()),
        progress(o.progress, 1 + o.bounces, mesh.vertex_count()),
        shadow_pool([this] { return ShadowScratch(ctx.options.order, setup.n, setup.samples); }),
        bounce_pool([this] { return BounceScratch(setup.n, setup.samples); }) {}
  BakeStats& stats;
  Clock::time_point start = Clock::now();
  Setup setup;
  std::unique_ptr<RayScene> scene;
  BakeContext ctx;
  ProgressReporter progress;
  ShadowPool shadow_pool;
  BouncePool bounce_pool;
  std::vector<std::uint8_t> flags;
  // Where bounces find vertex q in the previous pass (null: row q), and the frames in that
  // row order (set_row_order).
  const std::uint32_t* row_of = nullptr;
  std::vector<CornerFrame> frames;
  std::unique_ptr<CornerGather> gather;  // the bounces that read a pass from a file
  std::uint64_t shaded = 0;              // vertices through the shadow pass (a shard's range)
};

namespace {
const BakeOptions& checked(const meshes::Mesh& mesh, const BakeOptions& o, BakeStats& st) {
  validate(o);
  if (!mesh.has_frames()) {
    throw std::invalid_argument("bake: the mesh has no vertex frames (call compute_frames)");
  }
  st = BakeStats{};
  return o;
}
}  // namespace

BakeEngine::BakeEngine(const meshes::Mesh& mesh, const BakeOptions& o, BakeStats& stats)
    : state_(std::make_unique<State>(mesh, checked(mesh, o, stats), stats)) {
  BakeContext& ctx = state_->ctx;
  ctx.channels = o.material.channels();
  ctx.glossy = o.kind == TransferKind::kGlossy;
  ctx.offset = static_cast<float>(o.ray_offset * meshes::bounds(mesh).diagonal());
  ctx.faces = origin_faces(mesh, ctx.offset);
  ctx.vertex_count = mesh.vertex_count();
  const TransferSet s = shape();
  ctx.per_vertex = s.floats_per_vertex();
  ctx.per_channel = s.floats_per_channel();
  state_->flags.assign(ctx.vertex_count, 0);
}

BakeEngine::~BakeEngine() = default;

TransferSet BakeEngine::shape() const {
  const BakeContext& ctx = state_->ctx;
  const BakeOptions& o = ctx.options;
  TransferSet out;
  out.kind = o.kind;
  out.order = o.order;
  out.channels = o.material.channels();
  out.vertex_count = ctx.mesh.vertex_count();
  out.samples = state_->setup.samples;
  out.bounces = o.bounces;
  out.seed = o.seed;
  out.material = o.material;
  out.view_fit = o.view_fit;
  out.mesh_hash = meshes::content_hash(ctx.mesh);
  return out;
}

std::size_t BakeEngine::floats_per_vertex() const {
  return state_->ctx.per_vertex;
}
std::uint64_t BakeEngine::vertex_count() const {
  return state_->ctx.vertex_count;
}
void BakeEngine::start_pass(int pass) {
  if (state_->gather) state_->gather->clear();  // it holds the pass this one replaces
  state_->progress.start_pass(pass);
}
void BakeEngine::finish_pass() {
  state_->progress.finish_pass();
}

void BakeEngine::shadow(VertexList vertices, float* dst, std::vector<HitBlock>* hits) {
  const auto start = Clock::now();
  State& st = *state_;
  if (!st.scene) throw std::logic_error("BakeEngine::shadow after end_tracing");
  shadow_range(st.ctx, st.shadow_pool, vertices, dst, hits, st.flags, st.progress);
  st.shaded += vertices.size();
  st.stats.seconds_shadow += seconds_since(start);
}

void BakeEngine::end_tracing() {
  State& st = *state_;
  st.ctx.scene = nullptr;
  st.scene.reset();
  st.ctx.faces = OriginFaces{};
}

void BakeEngine::set_row_order(const std::uint32_t* row_of) {
  State& st = *state_;
  const meshes::Mesh& mesh = st.ctx.mesh;
  st.frames.resize(mesh.vertex_count());
  for (std::uint32_t q = 0; q < mesh.vertex_count(); ++q) {
    st.frames[row_of ? row_of[q] : q] =
        CornerFrame{mesh.tangents[q], mesh.bitangents[q], mesh.normals[q]};
  }
  st.row_of = row_of;
}

void BakeEngine::bounce(VertexList vertices, const std::vector<HitBlock>& hits,
                        const float* previous, float* dst) {
  const auto start = Clock::now();
  State& st = *state_;
  if (st.frames.empty()) set_row_order(nullptr);
  const BounceSource src{previous, st.row_of, st.frames.data(), st.ctx.per_vertex,
                         st.ctx.per_channel};
  bounce_range(st.ctx, st.bounce_pool, hits, src, vertices, 0, vertices.size(), dst, st.progress);
  st.stats.seconds_bounces += seconds_since(start);
}

void BakeEngine::bounce(VertexList vertices, const std::vector<HitBlock>& hits,
                        const PassReader& read, std::size_t cache_rows, float* dst) {
  const auto start = Clock::now();
  State& st = *state_;
  if (st.frames.empty()) set_row_order(nullptr);
  if (!st.gather)
    st.gather = std::make_unique<CornerGather>(st.ctx.mesh, st.ctx.per_vertex, cache_rows);
  CornerGather& gather = *st.gather;
  for (std::size_t first = 0; first < vertices.size();) {
    const std::size_t last = gather.collect(hits, first, vertices.size());
    gather.load(read, st.row_of);
    BounceSource src{gather.rows(), st.row_of, st.frames.data(), st.ctx.per_vertex,
                     st.ctx.per_channel};
    src.slot_of = gather.slot_of();
    bounce_range(st.ctx, st.bounce_pool, hits, src, vertices, first, last, dst, st.progress);
    first = last;
  }
  st.stats.seconds_bounces += seconds_since(start);
}

std::vector<std::uint32_t> index_range(std::uint64_t begin, std::uint64_t end) {
  std::vector<std::uint32_t> out(end - begin);
  std::iota(out.begin(), out.end(), std::uint32_t(begin));
  return out;
}

void BakeEngine::finish() {
  State& state = *state_;
  BakeStats& st = state.stats;
  for (std::uint64_t p = 0; p < state.flags.size(); ++p) {
    if (state.flags[p] & kNearly) st.occluded_vertices.push_back(std::uint32_t(p));
    if (state.flags[p] & kMoved) st.moved_origins.push_back(std::uint32_t(p));
  }
  st.rays_shadow = st.rays_bounce = 0;
  double occluded = 0;
  for (const ShadowScratch& s : state.shadow_pool) {
    st.rays_shadow += s.rays_shadow;
    st.rays_bounce += s.rays_bounce;
    occluded += double(s.occluded_count);
  }
  // Over the rays each vertex kept: a moved vertex's first, discarded trace is not counted.
  const double kept = double(state.shaded) * state.setup.samples;
  st.occluded_fraction = kept > 0 ? occluded / kept : 0.0;
  st.rows_gathered = state.gather ? state.gather->rows_read() : 0;
  st.seconds_total = seconds_since(state.start);
}

}  // namespace detail

TransferSet bake(const meshes::Mesh& mesh, const BakeOptions& o, BakeStats* stats) {
  BakeStats local_stats;
  detail::BakeEngine engine(mesh, o, stats ? *stats : local_stats);
  TransferSet out = engine.shape();
  const std::uint64_t v = engine.vertex_count();
  out.data.assign(v * engine.floats_per_vertex(), 0.f);
  std::vector<HitBlock> hits;
  const std::vector<std::uint32_t> all = detail::index_range(0, v);
  engine.start_pass(0);
  engine.shadow(all, out.data.data(), o.bounces > 0 ? &hits : nullptr);
  engine.finish_pass();
  if (o.bounces > 0) {
    std::vector<float> previous = out.data;  // M^{b-1}; starts as the shadow pass
    std::vector<float> current(out.data.size());
    for (int bounce = 1; bounce <= o.bounces; ++bounce) {
      engine.start_pass(bounce);
      engine.bounce(all, hits, previous.data(), current.data());
      engine.finish_pass();
      for (std::size_t i = 0; i < out.data.size(); ++i) out.data[i] += current[i];
      previous.swap(current);
    }
  }
  engine.finish();
  return out;
}

}  // namespace prt
