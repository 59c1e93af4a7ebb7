// prtr bake MESH -o FILE: per-vertex SH transfer (shadow + interreflection passes), streamed
// to the file block by block (prt::bake_to_file), so the payload never sits in memory whole.
#include "bake_flags.h"
#include "commands.h"
#include "meshes/load.h"
#include "pipeline.h"
#include "progress_bar.h"
#include "prt/transfer_file.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace prtr_app {
namespace {

// The bake with a progress bar; memory is bounded by the block, so no estimate is checked.
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

prt::TransferSet stream_bake(const meshes::Mesh& mesh, prt::BakeOptions options,
                             const std::string& output, std::uint64_t block,
                             std::pair<std::uint32_t, std::uint32_t> shard, bool quiet,
                             prt::BakeStats* stats) {
  if (shard.second > 0 && options.bounces > 0) {
    throw UsageError(
        "--shard needs --bounces 0: an interreflection pass reads every vertex's "
        "previous pass, so bake bounces in one process (it streams, so memory "
        "stays bounded)");
  }
  ProgressBar bar(quiet);
  options.progress = [&bar](const prt::BakeProgress& p) {
    bar.update(p.pass == 0 ? "shadow pass" : "bounce " + std::to_string(p.pass), p.done, p.total);
  };
  prt::TransferSet set =
      shard.second > 0
          ? prt::bake_shard_to_file(mesh, options, output, shard.first, shard.second, block, stats)
          : prt::bake_to_file(mesh, options, output, block, stats);
  bar.finish();
  return set;
}

}  // namespace

Runner add_bake_command(CLI::App& app) {
  struct Options {
    std::string mesh, output;
    BakeFlags flags;
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
  cmd->add_option("--block-vertices", opt->block,
                  "Vertices computed and written per block (0: about 64 MiB of transfer)")
      ->capture_default_str();
  cmd->add_option("--shard", opt->shard,
                  "k/n: bake only shard k (0-based) of n vertex ranges into a shard file for "
                  "prtr merge (needs --bounces 0)");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress bar");
  cmd->add_flag("--json", opt->json, "Print the summary as one JSON line instead");

  return [opt] {
    Options& o = *opt;
    prt::BakeOptions options = resolve_bake_flags(o.flags);
    const meshes::Mesh mesh = meshes::load_mesh(o.mesh);
    prt::BakeStats stats;
    const prt::TransferSet set = stream_bake(mesh, options, o.output, o.block, parse_shard(o.shard),
                                             o.quiet || o.json, &stats);

    // A sound closed or open surface rarely has a vertex that sees (almost) none of its sky,
    // so these are named: they render black and usually point at broken geometry.
    // Moved origins are named too: their vertex lies just inside the surface (a fold), which
    // the bake worked around but the mesh still has.
    auto ids = [](const std::vector<std::uint32_t>& v, std::string* json, std::string* text) {
      for (std::size_t i = 0; i < std::min<std::size_t>(v.size(), 8); ++i) {
        *json += (i ? "," : "") + std::to_string(v[i]);
        *text += (i ? ", " : " (") + std::to_string(v[i]);
      }
      if (!v.empty()) *text += v.size() > 8 ? ", ...)" : ")";
    };
    const std::vector<std::uint32_t>& dark = stats.occluded_vertices;
    const std::vector<std::uint32_t>& moved = stats.moved_origins;
    std::string dark_ids, dark_list, moved_ids, moved_list;
    ids(dark, &dark_ids, &dark_list);
    ids(moved, &moved_ids, &moved_list);
    if (o.json) {
      std::printf(
          "{\"vertices\":%zu,\"seconds_total\":%.4f,\"seconds_shadow\":%.4f,"
          "\"seconds_bounces\":%.4f,\"seconds_brdf\":%.4f,\"rays_shadow\":%llu,"
          "\"rays_bounce\":%llu,\"occluded_fraction\":%.6f,\"nearly_occluded_vertices\":%zu,"
          "\"nearly_occluded_ids\":[%s],\"moved_origin_vertices\":%zu,"
          "\"moved_origin_ids\":[%s]}\n",
          mesh.vertex_count(), stats.seconds_total, stats.seconds_shadow, stats.seconds_bounces,
          stats.seconds_brdf, (unsigned long long)stats.rays_shadow,
          (unsigned long long)stats.rays_bounce, stats.occluded_fraction, dark.size(),
          dark_ids.c_str(), moved.size(), moved_ids.c_str());
      return;
    }

    const double rays = double(stats.rays_shadow + stats.rays_bounce);
    std::printf("baked       %s -> %s\n", o.mesh.c_str(), o.output.c_str());
    std::printf("transfer    %s, order %d, %d channel(s), %zu vertices, %s\n",
                prt::transfer_kind_name(set.kind), set.order, set.channels, mesh.vertex_count(),
                format_bytes(set.vertex_count * set.floats_per_vertex() * sizeof(float)).c_str());
    std::printf("time        %.2f s total: %.2f s shadow, %.2f s bounces, %.2f s BRDF matrix\n",
                stats.seconds_total, stats.seconds_shadow, stats.seconds_bounces,
                stats.seconds_brdf);
    std::printf("rays        %.1f M (%.1f M shadow, %.1f M bounce), %.1f M rays/s\n", rays / 1e6,
                double(stats.rays_shadow) / 1e6, double(stats.rays_bounce) / 1e6,
                rays / 1e6 / (stats.seconds_shadow + stats.seconds_bounces));
    std::printf(
        "occluded    %.1f%% of shadow rays; %zu %s with < %g%% of rays escaping%s; %zu moved "
        "out from just inside the surface%s\n",
        100.0 * stats.occluded_fraction, dark.size(), dark.size() == 1 ? "vertex" : "vertices",
        100.0 * prt::kNearlyOccluded, dark_list.c_str(), moved.size(), moved_list.c_str());
  };
}

}  // namespace prtr_app
