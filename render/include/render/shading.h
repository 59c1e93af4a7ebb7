// render/shading.h: the per-frame lighting constants of CPCA rendering and the per-vertex
// radiance they give, computed on the CPU (thesis ch. 3.2, docs/ARCHITECTURE.md
// "Rendering").
//
// With l the rotated world-frame SH lighting (n x 3) and, for cluster k, mat(m_k) and
// mat(B_kj) the transfer matrices of its mean and components (n x n glossy, n x 1 diffuse),
//     a_k  = mat(m_k)  l,   b_kj = mat(B_kj) l       (per channel c: column c of l)
// and a vertex p of cluster k with weights w_pj has the exit-radiance SH vector
//     e_p = a_k + sum_j w_pj b_kj,   radiance toward world v = y(F_p^T v) . e_p[:, c]
// (glossy), or e_p itself (diffuse, view independent; there y is the constant 1).
// Glossy radiance toward a view below the local horizon, (F_p^T v).z < 0, is that toward the
// most grazing view above it (prt::clamp_to_horizon): at a silhouette the interpolated
// surface still faces the eye while the vertex's own plane does not. The view fit is defined
// up to the horizon; below it is the fit's free extension (prt/view_fit.h). Every path and
// every reference here clamps the same way.
//
// Constant layout, shared with the GLSL generator (render/shader_source.h) and matching
// cpca::registers_per_cluster: per cluster, terms t = 0 (the mean) .. N, then colour c,
// then row i (rows = n glossy, 1 diffuse), packed tightly as floats at
//     (t * 3 + c) * rows + i,
// the cluster padded to whole vec4s: registers = ceil((N + 1) * rows * 3 / 4).
#pragma once

#include "cpca/compressed.h"
#include "meshes/mesh.h"
#include "prt/projection.h"
#include "prt/transfer.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace render {

using Rgb = Eigen::Vector3f;

struct ConstantLayout {
  int order = 6;       // SH order of the exit radiance (glossy); 1 for diffuse
  int rows = 36;       // n glossy, 1 diffuse
  int terms = 9;       // N + 1
  bool glossy = true;  // evaluate the SH basis at the view direction

  int floats_per_cluster() const { return terms * 3 * rows; }
  int registers_per_cluster() const { return (floats_per_cluster() + 3) / 4; }
  int floats_stride() const { return registers_per_cluster() * 4; }
  int offset(int term, int colour, int row) const { return (term * 3 + colour) * rows + row; }
};

ConstantLayout constant_layout(const cpca::CompressedSet& set);
// The same for a set not compressed yet: SH `order`, glossy (transfer matrices) or diffuse,
// `components` PCs per cluster.
ConstantLayout constant_layout(int order, bool glossy, int components);

// Packs a compressed set's matrices once, then computes every frame's constants.
class ShadingConstants {
 public:
  explicit ShadingConstants(const cpca::CompressedSet& set);

  const ConstantLayout& layout() const { return layout_; }
  int cluster_count() const { return cluster_count_; }
  int coefficient_count() const { return order_ * order_; }
  // Cluster k's transfer rows, (N + 1) * channels * rows x n, row-major. Its constants are
  // these rows times l: constant (term, colour, i) is row(term, colour, i) times column colour.
  const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& rows(int k) const {
    return packed_[std::size_t(k)];
  }
  // Term t, channel c, row i is row (t * channels + c) * rows + i; a grey set's colours share
  // their rows.
  int row(int term, int colour, int i) const {
    return (term * channels_ + (channels_ == 1 ? 0 : colour)) * layout_.rows + i;
  }

  // Writes cluster k's constants to out + slot_of[k] * layout().floats_stride() (padding
  // floats are zeroed). Clusters run in parallel (TBB). `lighting` is n x 3, n = set order^2.
  void compute(const Eigen::Ref<const prt::ShLighting>& lighting,
               const std::vector<std::uint32_t>& slot_of, float* out) const;

 private:
  ConstantLayout layout_;
  int cluster_count_ = 0;
  int channels_ = 1, order_ = 6;
  // Per cluster, the (N + 1) * channels * rows x n matrix of transfer rows (row-major):
  // term t, channel c, row i is row (t * channels + c) * rows + i.
  std::vector<Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> packed_;
};

// Local-frame unit view direction at vertex p: F_p^T normalize(eye - position), clamped to
// the upper hemisphere (prt::clamp_to_horizon).
Eigen::Vector3d local_view(const meshes::Mesh& mesh, std::size_t p, const Eigen::Vector3d& eye);

// Fast CPU shading (the `cpu` render mode): per-vertex radiance from the constants of
// compute() with identity slots. `constants` holds cluster_count * floats_stride floats.
void shade_vertices(const cpca::CompressedSet& set, const ConstantLayout& layout,
                    const float* constants, const meshes::Mesh& mesh, const Eigen::Vector3d& eye,
                    std::vector<Rgb>& radiance);

// Reference: per vertex, reconstruct x_p in double (cpca::reconstruct_vertex), e_p =
// mat(x_p) l, and the SH basis by prt::sh_eval. Slow and obvious; tests compare GL to it.
std::vector<Rgb> reference_vertex_radiance(const cpca::CompressedSet& set, const meshes::Mesh& mesh,
                                           const Eigen::Ref<const prt::ShLighting>& lighting,
                                           const Eigen::Vector3d& eye);

// Uncompressed exit vectors e_p = M_p l for every vertex, laid out per vertex as
// [colour][row] (rows = n glossy, 1 diffuse): vertex p's floats start at p * 3 * rows.
// Blocked GEMMs in parallel.
void exit_vectors(const prt::TransferSet& transfer,
                  const Eigen::Ref<const prt::ShLighting>& lighting, std::vector<float>& out);

}  // namespace render
