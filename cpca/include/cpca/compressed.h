// cpca/compressed.h: a clustered-PCA compressed transfer set, in memory (thesis eq. 6,
// docs/ARCHITECTURE.md "Compression"). This is what the renderer consumes.
//
// The data compressed is one row per vertex, x_p = vec(M_p) over all channels, in the
// layout of prt::TransferSet: channel-major, then the row-major n x cols matrix
// (cols = n for glossy transfer, 1 for diffuse), so dimension = channels * n * cols.
// Vertex p belongs to cluster k = cluster_of[p] and is reconstructed as
//   x_p ~= mean_k + sum_j weights[p][j] * basis_k[j],
// with the N basis rows of a cluster orthonormal (or zero when the cluster's data has rank
// below N), and weights the projections of x_p - mean_k onto them.
#pragma once

#include "common/enum_names.h"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace cpca {

// How the clusters were formed; recorded in the compressed file for reports.
enum class ClusterMethod : std::uint32_t {
  kLbg = 0,           // LBG / k-means on the data, PCA per cluster afterwards (thesis "original")
  kIterative = 1,     // Sloan et al. 2003 iterative CPCA: reassign by reconstruction error
  kPatchFirst = 2,    // mesh cut into one patch per pass, CPCA inside each (patch_first.h)
  kJoint = 3,         // local search on error + lambda * overdraw (joint_search.h)
  kPatchJoint = 4,    // the joint search started from patch-first's clusters and passes
  kPatchEpsilon = 5,  // patch-first, then the least overdraw with Average SE <= a target
};
inline constexpr auto kClusterMethodNames = common::enum_table<ClusterMethod>(
    "clustering method", {{ClusterMethod::kLbg, "lbg"},
                          {ClusterMethod::kIterative, "iterative"},
                          {ClusterMethod::kPatchFirst, "patch-first"},
                          {ClusterMethod::kJoint, "joint"},
                          {ClusterMethod::kPatchJoint, "patch-joint"},
                          {ClusterMethod::kPatchEpsilon, "patch-eps"}});

enum class PcaSolver : std::uint32_t {
  kPowerIteration = 0,  // SLF paper Algorithm 1 (default)
  kEigen = 1,           // Eigen's SelfAdjointEigenSolver
};
inline constexpr auto kPcaSolverNames = common::enum_table<PcaSolver>(
    "PCA solver", {{PcaSolver::kPowerIteration, "power"}, {PcaSolver::kEigen, "eigen"}});

struct CompressedSet {
  // Layout of the source transfer (copied from the bake).
  int order = 6;                    // SH order; n = order^2
  int channels = 1;                 // 1 (grey) or 3 (RGB) transfer matrices per vertex
  int columns = 36;                 // n for glossy transfer matrices, 1 for diffuse vectors
  std::uint64_t mesh_hash = 0;      // meshes::content_hash of the baked mesh
  std::uint64_t transfer_hash = 0;  // FNV-1a of the transfer file's payload (staleness)
  std::string mesh_path{};  // the baked mesh as given to prtr bake, for tools needing geometry

  // Sizes.
  std::uint64_t vertex_count = 0;
  int cluster_count = 0;    // K
  int component_count = 0;  // N

  // How it was made (informational).
  ClusterMethod method = ClusterMethod::kLbg;
  PcaSolver solver = PcaSolver::kPowerIteration;
  double alpha = 0.0;               // geometry-coherence weight (0: off)
  bool overdraw_reduction = false;  // overdraw-aware reassignment applied
  std::uint64_t seed = 0;
  int iterations = 0;  // clustering iterations performed

  std::vector<std::uint32_t> cluster_of;  // V
  std::vector<float> weights{};           // V x N, row-major
  std::vector<float> means{};             // K x D, row-major
  std::vector<float> bases{};             // K x N x D: cluster k, component j, then D floats

  int coefficient_count() const { return order * order; }
  std::size_t dimension() const {
    return std::size_t(channels) * std::size_t(coefficient_count()) * std::size_t(columns);
  }
  bool glossy() const { return columns > 1; }

  using RowMap = Eigen::Map<const Eigen::Matrix<float, 1, Eigen::Dynamic>>;
  using BasisMap =
      Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
  RowMap mean(int k) const {
    return RowMap(means.data() + std::size_t(k) * dimension(), Eigen::Index(dimension()));
  }
  // N x D: the principal components of cluster k, one per row.
  BasisMap basis(int k) const {
    return BasisMap(bases.data() + std::size_t(k) * component_count * dimension(), component_count,
                    Eigen::Index(dimension()));
  }
  RowMap weight_row(std::uint64_t p) const {
    return RowMap(weights.data() + p * std::size_t(component_count), component_count);
  }
};

// Reconstruction of vertex p's data row (D floats) into `out`.
void reconstruct_vertex(const CompressedSet& set, std::uint64_t p, float* out);

// Checks every size and index for consistency (vector lengths, ids < K, finite values);
// throws std::invalid_argument naming the first problem. Used by the file loader and by
// code that builds sets by hand.
void validate(const CompressedSet& set);
// The same checks without the PRT layout's (order 1..10, columns 1 or n): for sets whose rows
// are another matrix's, such as a surface light field's 3 Z W radiances.
void validate_arrays(const CompressedSet& set);

}  // namespace cpca
