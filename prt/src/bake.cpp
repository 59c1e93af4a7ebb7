// The baker: shadow pass and interreflection passes (thesis ch. 3.1.1, eq. 1-3; Sloan,
// Kautz & Snyder 2002, section 5). See prt/bake.h for the formulation this file follows.
#include "prt/bake.h"

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
#include <fstream>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace prt {
namespace {

using Clock = std::chrono::steady_clock;
using MatF = Eigen::MatrixXf;  // column-major
using RowMatF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

constexpr std::uint64_t kChunk = 64;  // vertices per scheduling unit (and per hit block)

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

// An occluded ray that hit the front of a triangle: what a bounce needs of it.
struct HitRecord {
  std::uint16_t direction;  // index into Setup::directions
  std::int32_t triangle;
  float u, v;
};

// Front-hit records of kChunk consecutive vertices; offsets has kChunk + 1 entries.
struct HitBlock {
  std::vector<HitRecord> records;
  std::vector<std::uint32_t> offsets;
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

// Direction of each vertex's ray-origin offset: the normalised sum of the (area-weighted)
// normals of every triangle at its position, across split vertices too. On a welded mesh
// this is the vertex normal. Where a hard edge is modelled with split vertices (the open
// box's rims) it points between the faces, so the origin clears both: offsetting along the
// vertex's own normal leaves it on the other face's plane, where rays into that face slip
// through the crease and see the sky.
std::vector<meshes::Vec3> ray_offset_directions(const meshes::Mesh& mesh) {
  struct Key {
    float x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return std::hash<float>()(k.x) ^ (std::hash<float>()(k.y) * 31) ^
             (std::hash<float>()(k.z) * 131);
    }
  };
  std::unordered_map<Key, std::size_t, KeyHash> group_of;
  std::vector<std::size_t> group(mesh.vertex_count());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const meshes::Vec3& p = mesh.positions[v];
    group[v] = group_of.emplace(Key{p.x(), p.y(), p.z()}, group_of.size()).first->second;
  }
  std::vector<meshes::Vec3> sum(group_of.size(), meshes::Vec3::Zero());
  for (const meshes::Triangle& t : mesh.triangles) {
    const meshes::Vec3 face = (mesh.positions[t[1]] - mesh.positions[t[0]])
                                  .cross(mesh.positions[t[2]] - mesh.positions[t[0]]);
    for (int c = 0; c < 3; ++c) sum[group[t[c]]] += face;
  }
  std::vector<meshes::Vec3> dirs(mesh.vertex_count());
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    const meshes::Vec3 d = sum[group[v]].normalized();
    // Keep the origin above the vertex's own surface; fall back where the faces at a
    // position nearly cancel (a thin fin).
    dirs[v] = d.allFinite() && d.dot(mesh.normals[v]) > 0.2f ? d : mesh.normals[v];
  }
  return dirs;
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
      s.brdf.push_back(o.brdf_override ? o.brdf_override->cast<float>().eval()
                                       : brdf_matrix(o.material, o.order, c).cast<float>().eval());
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

TransferSet bake(const meshes::Mesh& mesh, const BakeOptions& o, BakeStats* stats) {
  validate(o);
  if (!mesh.has_frames()) {
    throw std::invalid_argument("bake: the mesh has no vertex frames (call compute_frames)");
  }
  const auto start_total = Clock::now();
  BakeStats local_stats;
  BakeStats& st = stats ? *stats : local_stats;
  st = BakeStats{};

  const int channels = o.material.channels();
  const bool glossy = o.kind == TransferKind::kGlossy;
  const Setup setup = make_setup(o, channels, &st.seconds_brdf);
  const int n = setup.n;
  const int samples = setup.samples;
  const std::uint64_t vertex_count = mesh.vertex_count();
  const float offset = static_cast<float>(o.ray_offset * meshes::bounds(mesh).diagonal());
  const std::vector<meshes::Vec3> offset_dirs = ray_offset_directions(mesh);

  TransferSet out;
  out.kind = o.kind;
  out.order = o.order;
  out.channels = channels;
  out.vertex_count = vertex_count;
  out.samples = samples;
  out.bounces = o.bounces;
  out.seed = o.seed;
  out.material = o.material;
  out.mesh_hash = meshes::content_hash(mesh);
  out.data.assign(vertex_count * out.floats_per_vertex(), 0.f);

  const RayScene scene(mesh);
  const std::uint64_t chunks = (vertex_count + kChunk - 1) / kChunk;
  std::vector<HitBlock> hit_blocks(o.bounces > 0 ? chunks : 0);
  ProgressReporter progress(o.progress, 1 + o.bounces, vertex_count);

  // Per-thread scratch, allocated once per thread and reused for every vertex.
  struct Scratch {
    explicit Scratch(int order) : rotation(order, Eigen::Matrix3d::Identity()) {}
    Eigen::Matrix3Xf world;
    std::vector<std::uint8_t> occluded;
    std::vector<int> occluded_index;
    MatF y_occluded, transfer, scratch;
    Eigen::VectorXf diffuse_local;
    Eigen::VectorXd diffuse_world;
    ShRotation rotation;  // D of the current vertex's frame, rebuilt in place
    std::vector<MatF> bands;
    Eigen::Matrix3Xf occluded_world;
    std::vector<RayHit> hits;
    std::uint64_t rays_shadow = 0, rays_bounce = 0, occluded_count = 0;
  };
  tbb::enumerable_thread_specific<Scratch> scratch_pool([&] {
    Scratch s(o.order);
    s.world.resize(3, samples);
    s.occluded.resize(samples);
    s.occluded_index.resize(samples);
    s.y_occluded.resize(n, samples);
    s.transfer.resize(n, n);
    s.scratch.resize(n, n);
    s.diffuse_local.resize(n);
    s.diffuse_world.resize(n);
    for (int l = 0; l < o.order; ++l) s.bands.emplace_back(2 * l + 1, 2 * l + 1);
    s.occluded_world.resize(3, samples);
    s.hits.resize(samples);
    return s;
  });

  // ---- Shadow pass -------------------------------------------------------------------------
  auto start_pass = Clock::now();
  progress.start_pass(0);
  tbb::parallel_for(std::uint64_t(0), chunks, [&](std::uint64_t chunk) {
    Scratch& s = scratch_pool.local();
    const std::uint64_t begin = chunk * kChunk, end = std::min(vertex_count, begin + kChunk);
    HitBlock* block = o.bounces > 0 ? &hit_blocks[chunk] : nullptr;
    if (block) block->offsets.assign(1, 0);
    for (std::uint64_t p = begin; p < end; ++p) {
      const Eigen::Matrix3f frame = frame_of(mesh, p);
      s.world.noalias() = frame * setup.directions;
      const Eigen::Vector3f origin = mesh.positions[p] + offset * offset_dirs[p];
      scene.occluded(origin, s.world, 0.f, s.occluded.data());
      int k = 0;
      for (int d = 0; d < samples; ++d) {
        if (!s.occluded[d]) continue;
        s.occluded_index[k] = d;
        s.y_occluded.col(k) = setup.y.col(d);
        ++k;
      }
      s.rays_shadow += samples;
      s.occluded_count += k;

      if (glossy) {
        // T = w Y Y^T - w Y_O Y_O^T as a symmetric rank-k update of the lower triangle.
        s.transfer = setup.gram;
        if (k > 0) {
          s.transfer.selfadjointView<Eigen::Lower>().rankUpdate(s.y_occluded.leftCols(k),
                                                                -setup.weight);
        }
        s.transfer.triangularView<Eigen::StrictlyUpper>() = s.transfer.transpose();
        s.rotation.set(frame.transpose().cast<double>());  // D(F^T): world to local
        multiply_bands_right(s.transfer, s.rotation, s.bands, s.scratch);
        for (int c = 0; c < channels; ++c) {
          Eigen::Map<RowMatF> m(out.transfer_data(p, c), n, n);
          m.noalias() = setup.brdf[c] * s.transfer;
        }
      } else {
        Eigen::VectorXf& t = s.diffuse_local;
        t = setup.cosine_projection;
        for (int j = 0; j < k; ++j) {
          t -= (setup.weight * setup.directions(2, s.occluded_index[j])) *
               setup.y.col(s.occluded_index[j]);
        }
        // World frame: t_world = D(F) t_local.
        s.rotation.set(frame.cast<double>());
        s.rotation.apply(t.cast<double>(), s.diffuse_world);
        for (int c = 0; c < channels; ++c) {
          Eigen::Map<Eigen::VectorXf>(out.transfer_data(p, c), n) =
              setup.rho_over_pi[c] * s.diffuse_world.cast<float>();
        }
      }

      if (block) {
        // Closest hits of the occluded rays, kept for every bounce.
        for (int j = 0; j < k; ++j) s.occluded_world.col(j) = s.world.col(s.occluded_index[j]);
        scene.intersect(origin, s.occluded_world.leftCols(k), 0.f, s.hits.data());
        s.rays_bounce += k;
        for (int j = 0; j < k; ++j) {
          const RayHit& h = s.hits[j];
          if (h.triangle < 0) continue;
          const meshes::Triangle& tri = mesh.triangles[h.triangle];
          const Eigen::Vector3f face = (mesh.positions[tri[1]] - mesh.positions[tri[0]])
                                           .cross(mesh.positions[tri[2]] - mesh.positions[tri[0]]);
          if (face.dot(s.occluded_world.col(j)) >= 0.f) continue;  // back face: no light
          block->records.push_back(
              HitRecord{std::uint16_t(s.occluded_index[j]), h.triangle, h.u, h.v});
        }
        block->offsets.push_back(std::uint32_t(block->records.size()));
      }
    }
    progress.add(end - begin);
  });
  progress.finish_pass();
  st.seconds_shadow = seconds_since(start_pass);

  // ---- Interreflection passes --------------------------------------------------------------
  start_pass = Clock::now();
  if (o.bounces > 0) {
    std::vector<float> previous = out.data;  // M^{b-1}; starts as the shadow pass
    std::vector<float> current(out.data.size());
    const std::size_t per_vertex = out.floats_per_vertex();
    const std::size_t per_channel = out.floats_per_channel();

    struct BounceScratch {
      Eigen::Matrix3Xf corner_dirs;
      ShBatchF corner_batch;
      MatF corner_y;
      MatF y_hit, transfer;
      RowMatF rows;  // row h is updated per hit: keep it contiguous
    };
    tbb::enumerable_thread_specific<BounceScratch> bounce_pool([&] {
      BounceScratch b;
      b.corner_dirs.resize(3, 3 * samples);
      b.y_hit.resize(n, samples);
      b.rows.resize(samples, n);
      b.transfer.resize(n, n);
      return b;
    });

    for (int bounce = 1; bounce <= o.bounces; ++bounce) {
      progress.start_pass(bounce);
      tbb::parallel_for(std::uint64_t(0), chunks, [&](std::uint64_t chunk) {
        BounceScratch& s = bounce_pool.local();
        const HitBlock& block = hit_blocks[chunk];
        const std::uint64_t begin = chunk * kChunk, end = std::min(vertex_count, begin + kChunk);
        for (std::uint64_t p = begin; p < end; ++p) {
          const HitRecord* hits = block.records.data() + block.offsets[p - begin];
          const int count = int(block.offsets[p - begin + 1] - block.offsets[p - begin]);
          float* dst = current.data() + p * per_vertex;
          if (count == 0) {
            std::fill(dst, dst + per_vertex, 0.f);
            continue;
          }
          const Eigen::Matrix3f frame = frame_of(mesh, p);
          // Directions toward p seen from each hit triangle's corners, in the corners' frames.
          if (glossy) {
            for (int h = 0; h < count; ++h) {
              const Eigen::Vector3f back = -(frame * setup.directions.col(hits[h].direction));
              const meshes::Triangle& tri = mesh.triangles[hits[h].triangle];
              for (int c = 0; c < 3; ++c) {
                const std::uint32_t q = tri[c];
                s.corner_dirs.col(3 * h + c) << mesh.tangents[q].dot(back),
                    mesh.bitangents[q].dot(back), mesh.normals[q].dot(back);
              }
            }
            sh_eval_batch(o.order, s.corner_dirs.leftCols(3 * count), s.corner_batch);
            s.corner_y = s.corner_batch;  // column-major: each corner's values contiguous
          }
          for (int h = 0; h < count; ++h) s.y_hit.col(h) = setup.y.col(hits[h].direction);

          for (int ch = 0; ch < channels; ++ch) {
            // rows.row(h): radiance the hit point sends toward p, as a function of lighting.
            s.rows.topRows(count).setZero();
            if (glossy) {
              for (int h = 0; h < count; ++h) {
                const meshes::Triangle& tri = mesh.triangles[hits[h].triangle];
                const float beta[3] = {1.f - hits[h].u - hits[h].v, hits[h].u, hits[h].v};
                for (int c = 0; c < 3; ++c) {
                  const float* src = previous.data() + tri[c] * per_vertex + ch * per_channel;
                  s.rows.row(h).noalias() += beta[c] * (s.corner_y.col(3 * h + c).transpose() *
                                                        Eigen::Map<const RowMatF>(src, n, n));
                }
              }
            } else {
              for (int h = 0; h < count; ++h) {
                const meshes::Triangle& tri = mesh.triangles[hits[h].triangle];
                const float beta[3] = {1.f - hits[h].u - hits[h].v, hits[h].u, hits[h].v};
                for (int c = 0; c < 3; ++c) {
                  const float* src = previous.data() + tri[c] * per_vertex + ch * per_channel;
                  s.rows.row(h) += beta[c] * Eigen::Map<const Eigen::RowVectorXf>(src, n);
                }
              }
            }
            float* out_ch = dst + ch * per_channel;
            if (glossy) {
              s.transfer.noalias() =
                  setup.weight * (s.y_hit.leftCols(count) * s.rows.topRows(count));
              Eigen::Map<RowMatF>(out_ch, n, n).noalias() = setup.brdf[ch] * s.transfer;
            } else {
              Eigen::Map<Eigen::RowVectorXf> t(out_ch, n);
              t.setZero();
              for (int h = 0; h < count; ++h) {
                t += setup.directions(2, hits[h].direction) * s.rows.row(h);
              }
              t *= setup.weight * setup.rho_over_pi[ch];
            }
          }
        }
        progress.add(end - begin);
      });
      progress.finish_pass();
      for (std::size_t i = 0; i < out.data.size(); ++i) out.data[i] += current[i];
      previous.swap(current);
    }
  }
  st.seconds_bounces = seconds_since(start_pass);

  for (const Scratch& s : scratch_pool) {
    st.rays_shadow += s.rays_shadow;
    st.rays_bounce += s.rays_bounce;
    st.occluded_fraction += double(s.occluded_count);
  }
  st.occluded_fraction = st.rays_shadow ? st.occluded_fraction / double(st.rays_shadow) : 0.0;
  st.seconds_total = seconds_since(start_total);
  return out;
}

}  // namespace prt
