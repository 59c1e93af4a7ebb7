// prtr bake MESH -o FILE: per-vertex SH transfer (shadow + interreflection passes), streamed
// to the file block by block (prt::bake_to_file), so the payload never sits in memory whole.
#include "bake_flags.h"
#include "commands.h"
#include "common/json.h"
#include "flag_checks.h"
#include "mesh_flags.h"
#include "meshes/load.h"
#include "mpi_world.h"
#include "pipeline/pipeline.h"
#include "progress_bar.h"
#include "prt/transfer_file.h"
#include "prt/transfer_shard.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace prtr_app {
using common::dump_json;
using common::Json;
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_bake {

// "k/n" as {k, n}; {0, 0} for no shard.
std::pair<std::uint32_t, std::uint32_t> parse_shard(const std::string& text) {
  if (text.empty()) return {0, 0};
  unsigned long k = 0, n = 0;
  char slash = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%lu%c%lu%c", &k, &slash, &n, &extra) != 3 || slash != '/' ||
      n == 0 || k >= n || n > 1000000) {
    throw UsageError("--shard " + text + ": expected k/n with 0 <= k < n (e.g. 0/4)");
  }
  return {std::uint32_t(k), std::uint32_t(n)};
}

// The bake with a progress bar; memory is bounded by the block, so no estimate is checked.
// `rank` (under mpirun) makes it one rank's part of a bake that all ranks write together.
prt::TransferSet stream_bake(const meshes::Mesh& mesh, prt::BakeOptions options,
                             const std::string& output, std::uint64_t block,
                             std::pair<std::uint32_t, std::uint32_t> shard, bool quiet,
                             prt::BakeStats* stats, const MpiWorld* rank = nullptr) {
  if (shard.second > 0 && options.bounces > 0) {
    throw UsageError(
        "--shard needs --bounces 0: an interreflection pass reads every vertex's "
        "previous pass, so bake bounces in one process (it streams, so memory "
        "stays bounded) or under mpirun");
  }
  ProgressBar bar(quiet);
  options.progress = [&bar](const prt::BakeProgress& p) {
    bar.update(p.pass == 0 ? "shadow pass" : "bounce " + std::to_string(p.pass), p.done, p.total);
  };
  prt::TransferSet set =
      rank ? prt::bake_rank(mesh, options, output, std::uint32_t(rank->rank),
                            std::uint32_t(rank->size), mpi_barrier, block, stats)
      : shard.second > 0
          ? prt::bake_shard_to_file(mesh, options, output, shard.first, shard.second, block, stats)
          : prt::bake_to_file(mesh, options, output, block, stats);
  bar.finish();
  return set;
}

// Under mpirun: rank r bakes vertex range r of R and writes its rows straight to their place
// in OUT.partial (prt::TransferSliceWriter), so nothing is merged; once every rank has
// closed its slice, rank 0 checksums the payload, writes the header and renames the file over
// the output (prt::commit_transfer_slices). With bounces, every pass goes through
// OUT.pass0/.pass1, which each rank writes its slice of and reads after a barrier
// (prt::bake_rank). A rank that fails aborts the whole job before the commit, so nothing
// appears at the output; a rerun rewrites the partial and pass files left behind.
prt::TransferSet mpi_bake(const meshes::Mesh& mesh, const prt::BakeOptions& options,
                          const std::string& output, std::uint64_t block, bool quiet,
                          prt::BakeStats* stats, MpiWorld world) {
  prt::TransferSet set;
  try {
    set =
        stream_bake(mesh, options, output, block, {0, 0}, quiet || world.rank != 0, stats, &world);
  } catch (const std::exception& e) {
    mpi_abort(std::string("bake of its vertex range failed: ") + e.what());
  }
  mpi_barrier();
  if (world.rank == 0) {
    try {
      prt::commit_transfer_slices(output, set);
      if (options.bounces > 0)
        for (const char* pass : {".pass0", ".pass1"}) std::filesystem::remove(output + pass);
    } catch (const std::exception& e) {
      mpi_abort(std::string("writing the output failed: ") + e.what());
    }
  }
  mpi_barrier();
  return set;
}

// Vertices that see (almost) none of their sky are named, because on a sound closed or open
// surface they are rare: they render black and usually point at broken geometry. Moved
// origins are named too: their vertex lies just inside the surface (a fold), which the bake
// worked around but the mesh still has. Both lists are cut at eight ids.
constexpr std::size_t kIdsShown = 8;

std::string id_list(const std::vector<std::uint32_t>& v) {
  std::string text;
  for (std::size_t i = 0; i < std::min(v.size(), kIdsShown); ++i) {
    text += (i ? ", " : " (") + std::to_string(v[i]);
  }
  if (!v.empty()) text += v.size() > kIdsShown ? ", ...)" : ")";
  return text;
}

Json summary_json(const meshes::Mesh& mesh, const prt::BakeStats& stats) {
  const auto first = [](const std::vector<std::uint32_t>& v) {
    return std::vector<std::uint32_t>(v.begin(), v.begin() + std::min(v.size(), kIdsShown));
  };
  Json j;
  j["vertices"] = mesh.vertex_count();
  j["seconds_total"] = stats.seconds_total;
  j["seconds_shadow"] = stats.seconds_shadow;
  j["seconds_bounces"] = stats.seconds_bounces;
  j["seconds_brdf"] = stats.seconds_brdf;
  j["rays_shadow"] = stats.rays_shadow;
  j["rays_bounce"] = stats.rays_bounce;
  j["rows_gathered"] = stats.rows_gathered;
  j["occluded_fraction"] = stats.occluded_fraction;
  j["nearly_occluded_vertices"] = stats.occluded_vertices.size();
  j["nearly_occluded_ids"] = first(stats.occluded_vertices);
  j["moved_origin_vertices"] = stats.moved_origins.size();
  j["moved_origin_ids"] = first(stats.moved_origins);
  return j;
}

void print_summary(const std::string& mesh_path, const std::string& output,
                   const meshes::Mesh& mesh, const prt::TransferSet& set,
                   const prt::BakeStats& stats) {
  const std::vector<std::uint32_t>& dark = stats.occluded_vertices;
  const std::vector<std::uint32_t>& moved = stats.moved_origins;
  const double rays = double(stats.rays_shadow + stats.rays_bounce);
  std::printf("baked       %s -> %s\n", mesh_path.c_str(), output.c_str());
  std::printf("transfer    %s, order %d, %d channel(s), %zu vertices, %s\n",
              prt::kTransferKindNames.name(set.kind), set.order, set.channels, mesh.vertex_count(),
              format_bytes(set.vertex_count * set.floats_per_vertex() * sizeof(float)).c_str());
  std::printf("time        %.2f s total: %.2f s shadow, %.2f s bounces, %.2f s BRDF matrix\n",
              stats.seconds_total, stats.seconds_shadow, stats.seconds_bounces, stats.seconds_brdf);
  std::printf("rays        %.1f M (%.1f M shadow, %.1f M bounce), %.1f M rays/s\n", rays / 1e6,
              double(stats.rays_shadow) / 1e6, double(stats.rays_bounce) / 1e6,
              rays / 1e6 / (stats.seconds_shadow + stats.seconds_bounces));
  std::printf(
      "occluded    %.1f%% of shadow rays; %zu %s with < %g%% of rays escaping%s; %zu moved "
      "out from just inside the surface%s\n",
      100.0 * stats.occluded_fraction, dark.size(), dark.size() == 1 ? "vertex" : "vertices",
      100.0 * prt::kNearlyOccluded, id_list(dark).c_str(), moved.size(), id_list(moved).c_str());
}

}  // namespace cmd_bake

Runner add_bake_command(CLI::App& app) {
  using namespace cmd_bake;
  struct Options {
    std::string mesh, output;
    BakeFlags flags;
    MeshFlags mesh_flags;
    bool quiet = false, json = false;
    std::uint64_t block = 0;
    std::string shard;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "bake", "Bake per-vertex SH transfer (shadow and interreflection passes) to a .prtx file");
  cmd->add_option("MESH", opt->mesh, std::string("Mesh file: ") + meshes::kMeshFormats)->required();
  cmd->add_option("-o,--output", opt->output, "Transfer file to write (.prtx)")->required();
  add_bake_flags(cmd, opt->flags);
  add_mesh_flags(cmd, opt->mesh_flags);
  cmd->add_option(
         "--block-vertices", opt->block,
         "Vertices computed and written per block (0: about 16 MiB of transfer); a bounce's "
         "cache of previous-pass rows holds " +
             std::to_string(prt::kGatherBlocks) + " blocks")
      ->check(integer_in(0, 1LL << 40))
      ->capture_default_str();
  cmd->add_option("--shard", opt->shard,
                  "k/n: bake only shard k (0-based) of n vertex ranges into a shard file for "
                  "prtr merge (needs --bounces 0)");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress bar");
  cmd->add_flag("--json", opt->json, "Print the summary as one JSON line instead");

  return [opt] {
    Options& o = *opt;
    check_outputs({{"-o", o.output}}, {{"MESH", o.mesh}});
    prt::BakeOptions options = resolve_bake_flags(o.flags);
    const meshes::Mesh mesh = meshes::load_mesh(o.mesh, load_options(o.mesh_flags));
    prt::BakeStats stats;
    const MpiWorld world = mpi_world();
    if (world.size > 1 && !o.shard.empty())
      throw UsageError("--shard and mpirun both split the vertices: use one of them");
    const prt::TransferSet set =
        world.size > 1
            ? mpi_bake(mesh, options, o.output, o.block, o.quiet || o.json, &stats, world)
            : stream_bake(mesh, options, o.output, o.block, parse_shard(o.shard), o.quiet || o.json,
                          &stats);
    if (world.rank != 0) return;

    if (o.json) {
      std::printf("%s\n", dump_json(summary_json(mesh, stats)).c_str());
    } else {
      print_summary(o.mesh, o.output, mesh, set, stats);
    }
  };
}

}  // namespace prtr_app
