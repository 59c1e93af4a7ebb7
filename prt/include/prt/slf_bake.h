// prt/slf_bake.h: the surface light field's data (SLF paper, Sec. 3.1): for every atlas texel
// that a lookup can read (meshes/atlas.h), the exit radiance toward every direction of the
// grid (prt/slf_directions.h) under a fixed probe, path traced (prt/path_tracer.h).
//
// The SLF matrix has one row per owned texel, in texel order (row-major over the atlas, the
// texels of triangle -1 skipped: slf_rows), and 3 Z W columns, (direction j Z + i, channel),
// RGB innermost, as render/slf_model.h lays out the view maps. A texel samples its surface
// point (the atlas's barycentrics) with the interpolated per-vertex frame. Entry (t, d) is the
// mean radiance over direction d's cell, not its centre: the `spp` paths take views spread
// over the cell (stratified in azimuth and cosine of the polar angle, so uniform in solid
// angle), so the grid is prefiltered. A view below the shading tangent plane gets the
// radiance of the most grazing view above it (prt::clamp_to_horizon), so silhouettes do not
// go dark. With `light_samples` (default 4) the paths' first light sample comes from
// light_samples x spp probe samples the texel traces once and every cell reuses, each paired
// with a view of its own, spread over the cell by a (0, 2)-sequence (prt::SharedLights,
// prt::sobol02): for the glossy bunny and horse under the forest probe the noise of the cells
// in front of their texel falls from 27 to 15 % in about the same time (docs/BENCHMARKS.md,
// "Bake noise").
//
// The .slf file holds the matrix (or a range of its rows, for processes that bake parts)
// after a 128-byte versioned header (common/binary_file.h), little-endian:
//   0 magic "PRTRSLFM", 8 u32 version, 12 u32 header bytes (128),
//   16 u16 atlas width, 18 u16 atlas charts (meshes::AtlasCharts), 20 u32 atlas height,
//   24 u32 Z (azimuth cells), 28 u32 W (polar cells),
//   32 u32 spp, 36 u16 bounces, 38 u16 light samples, 40 u32 material kind, 44 u16 masking,
//   46 u16 direction space (prt::SlfDirectionSpace), 48 u64 seed,
//   56 u64 mesh content hash, 64 f32[3] albedo, 76 f32 specular, 80 f32 exponent,
//   84 f32 roughness, 88 f32 f0, 92 u32 rows of the whole matrix, 96 u32 first row stored,
//   100 u32 rows stored, 104 u64 FNV-1a of the payload, 112 u64 FNV-1a of the probe's texels,
//   120 u64 FNV-1a of bytes [0, 120),
// then rows stored x 3 Z W float32, then nothing. Version 1 (still read) had a u32 atlas
// width at 16 and always per-triangle charts; its widths (at most 8192) left bytes 18-19 zero.
// Versions 1 and 2 had a u32 bounces at 36 and no shared light samples: they read as 0.
// Versions 1 to 3 had a u32 masking at 44 and view directions only.
#pragma once

#include "common/binary_file.h"
#include "meshes/atlas.h"
#include "meshes/mesh.h"
#include "probes/probe.h"
#include "prt/material.h"
#include "prt/slf_directions.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace prt {

inline constexpr std::uint32_t kSlfFileVersion = 4;
inline constexpr int kMaxLightSamples = 4096;  // SlfBakeOptions::light_samples

class SlfFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SlfBakeOptions {
  SlfGrid grid;
  int spp = 16;  // samples per texel and direction, in [1, 65536]
  // > 0: each path's first light sample is this many probe samples shared by all the
  // texel's paths (prt::SharedLights; light_samples x spp shadow rays a texel, the same for
  // every cell); 0: each path draws and traces its own. In [0, kMaxLightSamples].
  int light_samples = 4;
  int bounces = 1;  // interreflections (prt/path_tracer.h)
  std::uint64_t seed = 1;
  Material material;
  double ray_offset = 1e-4;
  // Rows [first_row, end_row) of the matrix; end_row 0 means to the last row.
  std::uint64_t first_row = 0, end_row = 0;
  // Rows per block written at once (0: about 16 MiB of floats).
  std::uint64_t block_rows = 0;
  // Rows done and rows of the range; from worker threads, one at a time, at most every 50 ms
  // and once at the end.
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  // Throws std::invalid_argument naming the option as its CLI flag.
  void validate() const;
};

// Everything about a matrix but its values.
struct SlfShape {
  int atlas_width = 0, atlas_height = 0;
  // How the atlas was cut: meshes::make_atlas(mesh, width, height, {charts}) rebuilds it.
  meshes::AtlasCharts charts = meshes::AtlasCharts::kConformal;
  SlfGrid grid;
  int spp = 0, bounces = 0;
  int light_samples = 0;  // SlfBakeOptions::light_samples
  std::uint64_t seed = 0;
  Material material;
  std::uint64_t mesh_hash = 0, probe_hash = 0;
  std::uint64_t rows = 0;                      // owned texels of the atlas
  std::uint64_t first_row = 0, row_count = 0;  // the rows this matrix or file holds
  std::size_t columns() const { return std::size_t(3) * std::size_t(grid.directions()); }
};

struct SlfMatrix {
  SlfShape shape;
  std::vector<float> data;  // row_count x columns, row-major
  const float* row(std::uint64_t r) const { return data.data() + r * shape.columns(); }
};

// Both SLF files (.slf here, pipeline's .slfc) record the bake's settings in the same header
// fields: bytes 16-47 (atlas size and charts, grid, spp, bounces, light samples, material
// kind and masking),
// 56-91 (mesh hash, albedo, specular, exponent, roughness, f0) and 112 (probe hash). Reading
// clamps counts to 2^30 so a hostile header cannot overflow an int; the caller validates
// (slf_settings_problem). A version 1 header (both files) reads as per-triangle charts, a
// version 1 or 2 header as no shared light samples, a version 1 to 3 header as view
// directions (masking a u32 at 44 there, a u16 beside the direction space from version 4).
void put_slf_settings(common::VersionedHeader& header, const SlfShape& shape);
void get_slf_settings(const common::VersionedHeader& header, SlfShape& shape);
// Empty when the chart method is one make_atlas knows and the direction space one the
// renderer knows; else the problem, naming it.
std::string slf_layout_problem(const SlfShape& shape);

// The owned texels of the atlas in texel order: row r of the SLF matrix samples texel
// slf_rows(atlas)[r] (y * width + x).
std::vector<std::uint32_t> slf_rows(const meshes::Atlas& atlas);

// FNV-1a of the probe's size and texels (the file records which probe lit the bake).
std::uint64_t probe_hash(const probes::Probe& probe);

// The rows of the options' range, in memory. The mesh needs frames; `atlas` must be
// make_atlas(mesh, ...) (its triangle count is checked). Throws std::invalid_argument for bad
// options, RayError if Embree fails.
SlfMatrix bake_slf(const meshes::Mesh& mesh, const meshes::Atlas& atlas, const probes::Probe& probe,
                   const SlfBakeOptions& options);

// The same, written to `path` block by block (memory holds one block), atomically: nothing
// appears at `path` unless the whole range was baked. Returns the shape written.
SlfShape bake_slf_to_file(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                          const probes::Probe& probe, const SlfBakeOptions& options,
                          const std::filesystem::path& path);

// Atomic; refuses (std::invalid_argument naming the file) what read_slf would refuse.
void write_slf(const std::filesystem::path& path, const SlfMatrix& matrix);
// Checks magic, version, fields, header checksum and the file size before reading, then the
// payload checksum and finite values. SlfFileError naming the file, the problem and the fix.
SlfMatrix read_slf(const std::filesystem::path& path);
SlfShape read_slf_header(const std::filesystem::path& path);

// Parts baked as row ranges, read and joined in row order into the whole matrix. Throws
// SlfFileError when they were baked with different settings or do not cover every row once.
SlfMatrix join_slf_parts(const std::vector<std::filesystem::path>& parts);

}  // namespace prt
