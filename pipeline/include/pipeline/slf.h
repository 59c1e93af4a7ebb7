// pipeline/slf.h: a surface light field as prtr slf makes it (SLF paper, Secs. 3.1-3.2):
// the atlas, the path-traced bake (cached), and CPCA of its matrix, with the figures the
// command prints.
//
// Cache: the bake's .slf goes to the cache directory (pipeline::default_cache_dir) as
// slf-<hash>.slf, the hash (FNV-1a) over the mesh's content hash, the probe's hash, the atlas
// size and charts and every bake option; an entry is read in full, checksum included, before it is
// used, and one that fails is reported and baked again. The compression is not cached: at
// the sizes the paper uses it costs a fraction of the bake.
#pragma once

#include "cpca/compress.h"
#include "meshes/mesh.h"
#include "pipeline/reporter.h"
#include "pipeline/slf_file.h"
#include "probes/probe.h"
#include "prt/slf_bake.h"
#include "prt/slf_filter.h"

#include <filesystem>
#include <string>

namespace pipeline {

struct SlfSettings {
  int atlas_width = 256, atlas_height = 256;
  meshes::AtlasCharts charts = meshes::AtlasCharts::kConformal;
  prt::SlfBakeOptions bake;        // its progress callback is replaced by the reporter's
  cpca::CompressOptions compress;  // its layout is set to the SLF's (pipeline/slf_file.h)
  // Applied to the bake before compression (the cache keeps the bake unfiltered); only to a
  // whole matrix, not to a range of rows.
  prt::SlfFilterOptions filter;
};

struct SlfRun {
  CompressedSlf slf;
  double bake_seconds = 0;      // data generation, wall time (the cache's read when it hit)
  double compress_seconds = 0;  // cpca::compress, wall time
  bool bake_cached = false;
  std::filesystem::path bake_path;  // the cache entry, empty without a cache
  cpca::CompressReport report;
  // Root mean square over all entries of the reconstruction minus the matrix compressed
  // (the bake after the texel filter), and the same relative to that matrix's own RMS.
  double rms_error = 0, relative_rms_error = 0;
  // Floats: V x D raw against V N + K (N + 1) D compressed (cluster ids not counted, as in
  // cpca's SizeMetrics), and their ratio.
  std::uint64_t raw_floats = 0, compressed_floats = 0;
  double ratio = 0;
};

// Makes the atlas, bakes (or reads the cached bake) and compresses. `cache_dir` empty: no
// cache. Throws std::invalid_argument for bad settings (an atlas too small for the mesh, more
// clusters than rows), and what the stages throw.
SlfRun make_slf(const meshes::Mesh& mesh, const std::string& mesh_path, const probes::Probe& probe,
                const std::string& probe_name, SlfSettings settings,
                const std::filesystem::path& cache_dir, const Reporter& reporter);

// The compression half of make_slf: the texel filter (a whole matrix only), CPCA of the
// matrix (its shape says which rows) and the figures, for a matrix baked elsewhere (prtr slf
// under mpirun joins the ranks' parts). `atlas` is the one the matrix was baked on. The bake
// fields of the result are left at zero. Throws std::invalid_argument for bad options (more
// clusters than rows) and a matrix whose data does not match its shape or atlas.
SlfRun compress_slf(const meshes::Mesh& mesh, const meshes::Atlas& atlas,
                    const std::string& mesh_path, const std::string& probe_name,
                    prt::SlfMatrix matrix, cpca::CompressOptions compress,
                    const prt::SlfFilterOptions& filter, const Reporter& reporter);

}  // namespace pipeline
