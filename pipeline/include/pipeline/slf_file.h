// pipeline/slf_file.h: the compressed surface light field file (.slfc): what the bake was
// made from (atlas size, direction grid, material, mesh path and content hash, probe name and
// hash) and the CPCA of its matrix (SLF paper, Sec. 3.2) as cpca::compress returns it.
//
// The compressed set's rows are the SLF matrix's (prt/slf_bake.h): one per owned texel, in
// texel order, 3 Z W floats each, (direction j Z + i, channel) with RGB innermost. cpca sizes a
// row as channels x order^2 x columns, so the set says order 1, channels 3, columns Z W;
// its channel-major reading of PRT transfer does not apply, the row is the SLF's as it is.
// The renderer's model (render/slf_model.h) takes it unchanged: texel_cluster and
// texel_weights scatter cluster_of and weights back to the atlas's texels (row r is texel
// prt::slf_rows(atlas)[r]), and view map (cluster, 0) is means row cluster, (cluster, 1 + j)
// bases row j of that cluster. The atlas itself is not stored: meshes::make_atlas(mesh,
// width, height, {charts}) is deterministic, so the mesh the content hash names rebuilds it.
//
// Layout, little-endian: a 128-byte versioned header (common/binary_file.h):
//   0 magic "PRTRSLFC", 8 u32 version, 12 u32 header bytes (128),
//   16 u16 atlas width, 18 u16 atlas charts (meshes::AtlasCharts), 20 u32 atlas height,
//   24 u32 Z, 28 u32 W, 32 u32 spp, 36 u16 bounces, 38 u16 light samples,
//   40 u32 material kind, 44 u16 masking, 46 u16 direction space (prt::SlfDirectionSpace),
//   48 u64 rows of the whole matrix (owned texels),
//   56 u64 mesh content hash, 64 f32[3] albedo, 76 f32 specular, 80 f32 exponent,
//   84 f32 roughness, 88 f32 f0, 92 u32 clusters K, 96 u32 components N,
//   100 u16 mesh path bytes, 102 u16 probe name bytes, 104 u64 FNV-1a of everything after
//   the header, 112 u64 probe hash (prt::probe_hash), 120 u64 FNV-1a of bytes [0, 120);
// then the mesh path and the probe name (each zero-padded to a multiple of 8 bytes), 48
// bytes of settings (u64 bake seed, u64 compression seed, u64 first row, u64 rows stored V,
// u32 clustering method, u32 PCA solver, u32 clustering iterations, u32 zero), cluster ids
// u32[V] (zero-padded to a multiple of 8 bytes), weights f32[V N], means f32[K D], bases
// f32[K N D] with D = 3 Z W; then nothing. A file normally stores every row (first row 0,
// V = rows); one made from a row range (a measurement) says so and the renderer refuses it.
// Version 1 (still read) had a u32 atlas width at 16 and always per-triangle charts;
// versions 1 and 2 a u32 bounces at 36 and no shared light samples (read as 0); versions 1
// to 3 a u32 masking at 44 and view directions only.
#pragma once

#include "cpca/compressed.h"
#include "prt/slf_bake.h"

#include <filesystem>
#include <stdexcept>
#include <string>

namespace pipeline {

inline constexpr std::uint32_t kSlfcFileVersion = 4;
inline constexpr std::size_t kMaxSlfcNameBytes = 4096;

class SlfcFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct CompressedSlf {
  prt::SlfShape bake;         // first_row and row_count: the rows `set` holds
  std::string mesh_path{};    // as given to prtr slf, made absolute
  std::string probe_name{};   // the probe's file name
  cpca::CompressedSet set{};  // layout order 1, channels 3, columns Z W (above)

  bool complete() const { return bake.first_row == 0 && bake.row_count == bake.rows; }
};

// Atomic; refuses (std::invalid_argument naming the file) what read_slfc would refuse.
void write_slfc(const std::filesystem::path& path, const CompressedSlf& slf);
// Checks magic, version, header fields and checksum, the file size against the sizes the
// header gives, then the payload checksum, cluster ids and finite values; SlfcFileError
// naming the file, the problem and the fix.
CompressedSlf read_slfc(const std::filesystem::path& path);

}  // namespace pipeline
