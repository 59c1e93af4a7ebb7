// The shadow pass (thesis ch. 3.1.1, eq. 1-2; Sloan, Kautz & Snyder 2002, section 5): each
// vertex traces its hemisphere of directions from its start points (bake_origins.h), and its
// transfer is the unoccluded one minus the occluded directions' share, rotated to the world
// frame; the occluded rays' front hits are kept for the bounces (bake_bounce.h).
#include "bake_shadow.h"

#include <tbb/parallel_for.h>

#include <optional>

namespace prt::detail {
namespace {

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
  ray_origins(ctx, p, s.world, s.origins);
  return trace_from_origins(ctx, s);
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

}  // namespace

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

}  // namespace prt::detail
