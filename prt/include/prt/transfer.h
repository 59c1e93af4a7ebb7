// prt/transfer.h: the result of a bake, in memory.
//
// Per vertex p and channel c:
//  - diffuse: a transfer vector t (n floats) with exit radiance t . l_c, where l_c is column
//    c of the world-frame SH lighting (n x 3). Exit radiance is view independent.
//  - glossy: an exit transfer matrix M (n x n floats, row-major) taking world-frame lighting
//    l_c to the local-frame SH coefficients of exit radiance: radiance toward the world
//    direction w is y(F_p^T w)^T M l_c, where F_p = [t b n] is the vertex frame.
// A grey material has one channel, applied to each of the three lighting columns; a
// coloured one has three, channel c applied to lighting column c.
// Layout of `data`: vertex-major, then channel, then the vector or row-major matrix, i.e.
// index ((p * channels + c) * rows + i) * cols + j with rows = n and cols = 1 or n.
#pragma once

#include "common/enum_names.h"

#include "prt/material.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace prt {

enum class TransferKind { kDiffuse, kGlossy };

inline constexpr auto kTransferKindNames = common::enum_table<TransferKind>(
    "transfer kind", {{TransferKind::kDiffuse, "diffuse"}, {TransferKind::kGlossy, "glossy"}});

struct TransferSet {
  TransferKind kind = TransferKind::kGlossy;
  int order = 6;
  int channels = 1;
  std::uint64_t vertex_count = 0;
  int samples = 0;         // hemisphere directions per vertex
  int bounces = 0;         // interreflection passes after the shadow pass
  std::uint64_t seed = 0;  // of the direction set
  Material material;
  ViewFit view_fit = kDefaultViewFit;  // glossy: how B's view side was fitted (prt/view_fit.h)
  std::uint64_t mesh_hash = 0;         // meshes::content_hash of the baked mesh
  // FNV-1a of the payload as recorded in the file this set was read from (0 for a set that
  // was never written); a compressed set records it to tie itself to this bake.
  std::uint64_t payload_checksum = 0;
  std::vector<float> data;

  int coefficient_count() const { return order * order; }
  int columns() const { return kind == TransferKind::kGlossy ? coefficient_count() : 1; }
  std::size_t floats_per_channel() const {
    return std::size_t(coefficient_count()) * std::size_t(columns());
  }
  std::size_t floats_per_vertex() const { return floats_per_channel() * std::size_t(channels); }

  // Glossy: the n x n matrix of vertex p, channel c. Diffuse: an n x 1 column.
  using MatrixView =
      Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
  MatrixView transfer(std::uint64_t vertex, int channel) const {
    return MatrixView(
        data.data() + vertex * floats_per_vertex() + std::size_t(channel) * floats_per_channel(),
        coefficient_count(), columns());
  }
  float* transfer_data(std::uint64_t vertex, int channel) {
    return data.data() + vertex * floats_per_vertex() + std::size_t(channel) * floats_per_channel();
  }
};

}  // namespace prt
