// The interreflection passes (thesis ch. 3.1.1, eq. 3; Sloan, Kautz & Snyder 2002, section 5):
// per vertex, the light its front hits send back, each hit's radiance interpolated from the
// previous bounce's transfer at its triangle's corners (glossy corners seen from the
// direction back to the vertex, clamped to their horizon as in prt/view_fit.h). The corner
// kernel rounds exactly as Eigen's product does, so every path gives the same bits.
#include "bake_bounce.h"

#include "prt/view_fit.h"

#include <tbb/parallel_for.h>

#include <cmath>

namespace prt::detail {
namespace {

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

}  // namespace

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

}  // namespace prt::detail
