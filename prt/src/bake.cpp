// The baker's engine (thesis ch. 3.1.1, eq. 1-3; Sloan, Kautz & Snyder 2002, section 5): the
// shared direction set, the options' checks and the memory estimate, and BakeEngine, which
// runs the shadow pass (bake_shadow.h) and the interreflection passes (bake_bounce.h) over
// ranges of vertices for the whole-mesh bake here and the streaming bake
// (bake_stream.cpp). See prt/bake.h for the formulation.
#include "prt/bake.h"

#include "bake_bounce.h"
#include "bake_context.h"
#include "bake_engine.h"
#include "bake_shadow.h"
#include "corner_gather.h"

#include "prt/ray_scene.h"
#include "prt/sampling.h"
#include "prt/sh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <memory>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>

namespace prt {
namespace detail {
namespace {

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

void populate_pages(void* start, std::size_t bytes) {
  const auto page = std::uintptr_t(sysconf(_SC_PAGESIZE));
  const auto address = reinterpret_cast<std::uintptr_t>(start);
  const std::uintptr_t begin = (address + page - 1) / page * page;
  const std::uintptr_t end = (address + bytes) / page * page;
  if (page == 0 || end <= begin) return;
  const std::uintptr_t chunk = 512 * page;
  const std::size_t chunks = std::size_t((end - begin + chunk - 1) / chunk);
  tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t i) {
    const std::uintptr_t first = begin + i * chunk;
    // A kernel without MADV_POPULATE_WRITE (before 5.14) refuses it: the pages then fault in
    // at the first write, as without this call.
    madvise(reinterpret_cast<void*>(first), std::min(chunk, end - first), MADV_POPULATE_WRITE);
  });
}

namespace {

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
}  // namespace detail

using detail::HitBlock;
using detail::HitRecord;

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
    throw std::invalid_argument(std::string("--view-fit ") + kViewFitNames.name(o.view_fit) +
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
  // The output's pages faulted in on every thread before the (then bandwidth-bound) zeroing:
  // page faults on one thread were most of the bake's serial remainder (186 MB for the bunny
  // at order 6).
  const std::size_t floats = engine.vertex_count() * engine.floats_per_vertex();
  out.data.reserve(floats);
  detail::populate_pages(out.data.data(), floats * sizeof(float));
  out.data.resize(floats);
  std::vector<HitBlock> hits;
  const std::vector<std::uint32_t> all = detail::index_range(0, engine.vertex_count());
  engine.start_pass(0);
  engine.shadow(all, out.data.data(), o.bounces > 0 ? &hits : nullptr);
  engine.finish_pass();
  if (o.bounces > 0) {
    // A bounce writes every float of its pass, so its buffers are left unzeroed (their pages
    // are first touched by the bounce's own threads); the first bounce reads the shadow pass
    // in place.
    const std::size_t size = out.data.size();
    std::unique_ptr<float[]> current(new float[size]);
    std::unique_ptr<float[]> before;  // M^{b-1} from the second bounce on
    const float* previous = out.data.data();
    for (int bounce = 1; bounce <= o.bounces; ++bounce) {
      engine.start_pass(bounce);
      engine.bounce(all, hits, previous, current.get());
      engine.finish_pass();
      float* sum = out.data.data();
      const float* add = current.get();
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, size, std::size_t(1) << 16),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i < r.end(); ++i) sum[i] += add[i];
                        });
      if (bounce == o.bounces) break;
      if (!before) before.reset(new float[size]);
      std::swap(current, before);
      previous = before.get();
    }
  }
  engine.finish();
  return out;
}

}  // namespace prt
