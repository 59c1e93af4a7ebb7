// prtr bake MESH -o FILE: per-vertex SH transfer (shadow + interreflection passes).
#include "bake_flags.h"
#include "commands.h"
#include "meshes/load.h"
#include "pipeline.h"
#include "progress_bar.h"
#include "prt/transfer_file.h"

#include <cstdio>
#include <string>

namespace prtr_app {

Runner add_bake_command(CLI::App& app) {
  struct Options {
    std::string mesh, output;
    BakeFlags flags;
    bool quiet = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "bake", "Bake per-vertex SH transfer (shadow and interreflection passes) to a .prtx file");
  cmd->add_option("MESH", opt->mesh, "Mesh file (OBJ, PLY, OFF, STL)")->required();
  cmd->add_option("-o,--output", opt->output, "Transfer file to write (.prtx)")->required();
  add_bake_flags(cmd, opt->flags);
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress bar");

  return [opt] {
    Options& o = *opt;
    const prt::BakeOptions options = resolve_bake_flags(o.flags);
    const meshes::Mesh mesh = meshes::load_mesh(o.mesh);
    prt::BakeStats stats;
    const prt::TransferSet set = run_bake(mesh, o.mesh, options, o.quiet, &stats);
    prt::write_transfer(o.output, set);

    const double rays = double(stats.rays_shadow + stats.rays_bounce);
    std::printf("baked       %s -> %s\n", o.mesh.c_str(), o.output.c_str());
    std::printf("transfer    %s, order %d, %d channel(s), %zu vertices, %s\n",
                prt::transfer_kind_name(set.kind), set.order, set.channels, mesh.vertex_count(),
                format_bytes(set.data.size() * sizeof(float)).c_str());
    std::printf("time        %.2f s total: %.2f s shadow, %.2f s bounces, %.2f s BRDF matrix\n",
                stats.seconds_total, stats.seconds_shadow, stats.seconds_bounces,
                stats.seconds_brdf);
    std::printf("rays        %.1f M (%.1f M shadow, %.1f M bounce), %.1f M rays/s\n", rays / 1e6,
                double(stats.rays_shadow) / 1e6, double(stats.rays_bounce) / 1e6,
                rays / 1e6 / (stats.seconds_shadow + stats.seconds_bounces));
    std::printf("occluded    %.1f%% of shadow rays\n", 100.0 * stats.occluded_fraction);
  };
}

}  // namespace prtr_app
