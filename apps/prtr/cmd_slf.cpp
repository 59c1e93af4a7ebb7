// prtr slf MESH --probe P -o OUT.slfc: a surface light field (SLF paper, Secs. 3.1-3.2): an
// atlas of --samples texels (--charts: conformal charts of many triangles, or one per
// triangle as files of version 1 had), the exit radiance of every texel toward --directions
// cells path traced under the probe (cached), CPCA of that matrix, and the figures the
// paper's Table 1 reports: data generation time, compression time, compression ratio, and
// the RMS error of the compressed matrix against the baked one. Under mpirun the ranks bake
// row ranges and rank 0 compresses: the same file as one process.
#include "bake_flags.h"
#include "commands.h"
#include "common/json.h"
#include "compress_flags.h"
#include "flag_checks.h"
#include "mesh_flags.h"
#include "mpi_world.h"
#include "progress_bar.h"
#include "slf_flags.h"

#include "meshes/atlas.h"
#include "meshes/load.h"
#include "pipeline/pipeline.h"
#include "pipeline/slf.h"
#include "probes/load.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace prtr_app {
using common::dump_json;
using common::Json;
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_slf {

namespace fs = std::filesystem;

struct Options {
  std::string mesh, probe, output, cache, rows;
  SlfFlags slf;
  MaterialFlags material;
  MeshFlags mesh_flags;
  CompressFlags compress;
  int bounces = 1;
  std::uint64_t seed = 1;
  double ray_offset = 1e-4;
  bool quiet = false, json = false, no_cache = false;
};

// "A:B" as rows [A, B); {0, 0} for all rows.
std::pair<std::uint64_t, std::uint64_t> parse_rows(const std::string& text) {
  if (text.empty()) return {0, 0};
  unsigned long long a = 0, b = 0;
  char colon = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%llu%c%llu%c", &a, &colon, &b, &extra) != 3 || colon != ':' ||
      b <= a || b > (1ULL << 32)) {
    throw UsageError("--rows " + text + ": expected FIRST:END with FIRST < END (e.g. 0:65536)");
  }
  return {a, b};
}

void add_flags(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.mesh, "Mesh (" + std::string(meshes::kMeshFormats) + ")")->required();
  cmd->add_option("--probe", o.probe, "Light probe (lat-long or angular EXR/HDR)")->required();
  cmd->add_option("-o,--output", o.output, "Compressed surface light field to write (.slfc)")
      ->required();
  add_slf_flags(cmd, o.slf, "--samples");
  add_checked_option(cmd, "--bounces", o.bounces, "Interreflections (0: direct light, shadows)",
                     integer_in(0, 16));
  add_checked_option(cmd, "--seed", o.seed, "Seed of the path tracer's random numbers",
                     unsigned_integer());
  add_checked_option(cmd, "--ray-offset", o.ray_offset,
                     "Secondary rays start this x the bbox diagonal off the surface",
                     number_in(1e-8, 0.1));
  cmd->add_option("--rows", o.rows,
                  "Bake and compress only rows FIRST:END of the matrix (a part or a "
                  "measurement; the renderer refuses such a file)");
  add_material_flags(cmd, o.material);
  add_compress_flags(cmd, o.compress, CompressFlagSet::kPipeline);
  add_mesh_flags(cmd, o.mesh_flags);
  cmd->add_option("--cache", o.cache, "Cache directory (default $PRTR_CACHE or ~/.cache/prtr)");
  cmd->add_flag("--no-cache", o.no_cache, "Bake in memory, neither reading nor writing the cache");
  cmd->add_flag("--json", o.json, "Print the report as one JSON line instead");
  cmd->add_flag("-q,--quiet", o.quiet, "No progress bar");
}

// Under mpirun: rank r of n bakes rows [r R / n, (r + 1) R / n) into OUT.part<r> (the ranks
// share the output's file system, as prtr bake's ranks do); after a barrier rank 0 joins the
// parts (prt::join_slf_parts), compresses, writes OUT and removes them. A row's random numbers
// are keyed by its index, so the joined matrix is the one-process bake's and the file its
// bytes. The cache is neither read nor written. A rank that fails ends the whole job before
// anything appears at OUT.
pipeline::SlfRun mpi_slf(const Options& o, const meshes::Mesh& mesh, const probes::Probe& probe,
                         const std::string& probe_name, pipeline::SlfSettings settings,
                         MpiWorld world) {
  if (!o.rows.empty()) throw UsageError("--rows and mpirun both split the rows: use one of them");
  meshes::Atlas atlas;
  try {
    atlas =
        meshes::make_atlas(mesh, settings.atlas_width, settings.atlas_height, {settings.charts});
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());  // an atlas too small for the mesh
  }
  const std::uint64_t rows = atlas.used_texels();
  const std::uint64_t ranks = std::uint64_t(world.size);
  if (rows < ranks || rows < std::uint64_t(std::max(1, settings.compress.clusters)))
    throw UsageError("mpirun -np " + std::to_string(world.size) + " with --clusters " +
                     std::to_string(settings.compress.clusters) + ": the atlas has only " +
                     std::to_string(rows) +
                     " rows (texels); use fewer ranks or clusters, or a "
                     "larger --samples atlas");
  const auto part = [&o](int rank) { return fs::path(o.output + ".part" + std::to_string(rank)); };
  const bool quiet = o.quiet || o.json || world.rank != 0;
  const auto start = std::chrono::steady_clock::now();
  {
    const MpiCoreShare cores;  // the ranks on one node share its cores while they bake
    try {
      prt::SlfBakeOptions bake = settings.bake;
      bake.first_row = rows * std::uint64_t(world.rank) / ranks;
      bake.end_row = rows * std::uint64_t(world.rank + 1) / ranks;
      ProgressBar bar(quiet);
      bake.progress = [&bar](std::uint64_t done, std::uint64_t total) {
        bar.update("slf bake (rank 0's rows)", done, total);
      };
      prt::bake_slf_to_file(mesh, atlas, probe, bake, part(world.rank));
      bar.finish();
    } catch (const std::exception& e) {
      mpi_abort(std::string("slf bake of its rows failed: ") + e.what());
    }
  }
  mpi_barrier();
  pipeline::SlfRun r;
  if (world.rank == 0) {
    try {
      std::vector<fs::path> parts;
      for (int rank = 0; rank < world.size; ++rank) parts.push_back(part(rank));
      prt::SlfMatrix matrix = prt::join_slf_parts(parts);
      const double bake_seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      r = pipeline::compress_slf(mesh, atlas, o.mesh, probe_name, std::move(matrix),
                                 settings.compress, settings.filter, stderr_reporter(quiet));
      r.bake_seconds = bake_seconds;
      pipeline::write_slfc(o.output, r.slf);
      for (const fs::path& p : parts) fs::remove(p);
    } catch (const std::exception& e) {
      mpi_abort(std::string("joining, compressing or writing failed: ") + e.what());
    }
  }
  mpi_barrier();
  return r;
}

void run(const Options& o, CLI::App*) {
  check_outputs({{"-o", o.output}}, {{"MESH", o.mesh}, {"--probe", o.probe}});
  pipeline::SlfSettings settings;
  resolve_slf_flags(o.slf, settings);
  std::tie(settings.bake.first_row, settings.bake.end_row) = parse_rows(o.rows);
  settings.bake.bounces = o.bounces;
  settings.bake.seed = o.seed;
  settings.bake.ray_offset = o.ray_offset;
  settings.bake.material = resolve_material_flags(o.material);
  settings.compress = resolve_compress_flags(o.compress);
  check_slf_settings(settings);
  const meshes::Mesh mesh = meshes::load_mesh(o.mesh, load_options(o.mesh_flags));
  const probes::Probe probe = probes::load_probe(o.probe);
  const std::string probe_name = fs::path(o.probe).filename().string();
  const MpiWorld world = mpi_world();
  pipeline::SlfRun r;
  if (world.size > 1) {
    r = mpi_slf(o, mesh, probe, probe_name, settings, world);
    if (world.rank != 0) return;
  } else {
    const fs::path cache = o.no_cache        ? fs::path()
                           : o.cache.empty() ? pipeline::default_cache_dir()
                                             : fs::path(o.cache);
    try {
      r = pipeline::make_slf(mesh, o.mesh, probe, probe_name, settings, cache,
                             stderr_reporter(o.quiet || o.json));
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());  // an atlas too small for the mesh, too many clusters
    }
    pipeline::write_slfc(o.output, r.slf);
  }

  const std::uint64_t file_bytes = fs::file_size(o.output);
  if (o.json) {
    Json j;
    j["rows"] = r.slf.bake.row_count;
    j["atlas_rows"] = r.slf.bake.rows;
    j["atlas_charts"] = meshes::kAtlasChartsNames.name(r.slf.bake.charts);
    j["directions"] = r.slf.bake.grid.directions();
    j["direction_space"] = prt::kSlfDirectionSpaceNames.name(r.slf.bake.grid.space);
    j["data_generation_seconds"] = r.bake_seconds;
    j["bake_cached"] = r.bake_cached;
    j["compression_seconds"] = r.compress_seconds;
    j["compression_ratio"] = r.ratio;
    j["rms_error"] = r.rms_error;
    j["relative_rms_error"] = r.relative_rms_error;
    j["file_bytes"] = file_bytes;
    std::printf("%s\n", dump_json(j).c_str());
    return;
  }
  std::printf("wrote %s (%s)\n", o.output.c_str(), format_bytes(file_bytes).c_str());
  std::printf("rows (texels)      %llu of %llu, x %d %s directions x 3 channels\n",
              static_cast<unsigned long long>(r.slf.bake.row_count),
              static_cast<unsigned long long>(r.slf.bake.rows), r.slf.bake.grid.directions(),
              std::string(prt::kSlfDirectionSpaceNames.name(r.slf.bake.grid.space)).c_str());
  std::printf("data generation    %.2f s%s\n", r.bake_seconds,
              r.bake_cached ? " (read from the cache; the bake itself was earlier)" : "");
  std::printf("compression        %.2f s (K = %d clusters, N = %d components)\n",
              r.compress_seconds, r.slf.set.cluster_count, r.slf.set.component_count);
  std::printf("compression ratio  %.1f : 1 (%llu floats raw, %llu compressed)\n", r.ratio,
              static_cast<unsigned long long>(r.raw_floats),
              static_cast<unsigned long long>(r.compressed_floats));
  std::printf("RMS error          %.4g (%.3g%% of the matrix's RMS)\n", r.rms_error,
              100 * r.relative_rms_error);
}

}  // namespace cmd_slf

Runner add_slf_command(CLI::App& app) {
  return add_command(app, "slf",
                     "Bake a surface light field (path traced under a probe) and compress it "
                     "with CPCA into a .slfc file",
                     cmd_slf::add_flags, cmd_slf::run);
}

}  // namespace prtr_app
