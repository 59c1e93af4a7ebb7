// pipeline/pipeline.h: bake and compress as the commands run them (progress and notes through
// a Reporter, memory check), and a content-addressed cache so that prtr relight / overdraw /
// render with the same inputs skip both.
//
// Cache: files in one directory (default $PRTR_CACHE, else $XDG_CACHE_HOME/prtr, else
// ~/.cache/prtr), named by an FNV-1a hash of everything that determines them:
//   bake-<hash>.prtx   mesh content hash + every bake option
//   cpca-<hash>.prtc   transfer payload checksum + every compression option
//   cpca-<hash>.summary  that compression's clustering time and errors, one JSON object:
//                        {"clustering_seconds": s, "average_se": e, "relative_error": r}
// Entries are written atomically, so an interrupted run leaves no entry (never half of one),
// and the temporaries of runs killed mid-write are swept on the next lookup. An entry is read
// in full, payload checksum included, before it is trusted; one that fails is reported,
// deleted and rebuilt, so a damaged cache costs a rebuild, never a failed run.
#pragma once

#include "cpca/compress.h"
#include "cpca/compressed.h"
#include "meshes/mesh.h"
#include "pipeline/reporter.h"
#include "prt/bake.h"
#include "prt/transfer.h"

#include <filesystem>
#include <string>

namespace pipeline {

cpca::Geometry geometry_of(const meshes::Mesh& mesh);

// Bakes after checking the memory estimate (told to `reporter` first); throws a runtime_error
// naming the mesh when it would not fit.
prt::TransferSet run_bake(const meshes::Mesh& mesh, const std::string& mesh_name,
                          prt::BakeOptions options, const Reporter& reporter,
                          prt::BakeStats* stats = nullptr);

// Compresses a transfer set of `mesh` (checked to match), its progress to `reporter`; fills
// the set's hashes and mesh path.
cpca::CompressedSet run_compress(const prt::TransferSet& transfer, const meshes::Mesh& mesh,
                                 const std::string& mesh_path, cpca::CompressOptions options,
                                 const Reporter& reporter, cpca::CompressReport* report = nullptr);
// The same over rows visited in blocks (an out-of-core .prtx, prt/mapped_transfer.h):
// `transfer` gives the header fields, its data is not used. With a `distribution`, every
// rank calls this and rank 0 gets the set (cpca/compress.h).
cpca::CompressedSet run_compress(const prt::TransferSet& transfer, const cpca::RowBlocks& data,
                                 const meshes::Mesh& mesh, const std::string& mesh_path,
                                 cpca::CompressOptions options, const Reporter& reporter,
                                 cpca::CompressReport* report = nullptr,
                                 cpca::Distribution* distribution = nullptr);

std::filesystem::path default_cache_dir();

struct CacheResult {
  std::filesystem::path path;
  bool hit = false;
};

// How much of a cached bake is checked before it is used: its header against the settings
// its name hashes (cheap), or its whole payload against the header's checksum too (reads the
// whole file: 1.2 s for the main job's 180 MB).
enum class BakeCheck { kHeader, kPayload };

// The cached bake of `mesh` with `options`, baking it when missing or damaged.
CacheResult cached_bake(const meshes::Mesh& mesh, const std::string& mesh_name,
                        const prt::BakeOptions& options, const std::filesystem::path& cache_dir,
                        const Reporter& reporter, BakeCheck check = BakeCheck::kPayload);

// What a compression measured about itself, kept beside the cached set (a `.summary` file)
// so that a cache hit can still report it.
struct CompressionSummary {
  double clustering_seconds = 0, average_se = 0, relative_error = 0;
};

struct CompressCacheResult : CacheResult {
  CompressionSummary summary;
};

// The cached compression of the transfer file `transfer_path`; `rebuild` ignores an existing
// entry (and replaces it).
CompressCacheResult cached_compress(const std::filesystem::path& transfer_path,
                                    const meshes::Mesh& mesh, const std::string& mesh_path,
                                    const cpca::CompressOptions& options,
                                    const std::filesystem::path& cache_dir,
                                    const Reporter& reporter, bool rebuild = false);

struct CachedPair {
  CacheResult transfer;
  CompressCacheResult compressed;
  double bake_seconds = 0, compress_seconds = 0;  // wall time of each step, cached or not
};

// Bake and compress through the cache. The compression's key holds the bake's checksum, so
// a cached compression needs only the bake's header; the bake's payload is read, and
// verified, only when the compression is built from it, and a damaged one is then rebaked.
CachedPair cached_bake_and_compress(const meshes::Mesh& mesh, const std::string& mesh_path,
                                    const prt::BakeOptions& bake,
                                    const cpca::CompressOptions& compress,
                                    const std::filesystem::path& cache_dir,
                                    const Reporter& reporter);

}  // namespace pipeline
