#include "slf_flags.h"

#include "commands.h"
#include "flag_checks.h"

#include <cstdio>
#include <stdexcept>
#include <utility>

namespace prtr_app {
namespace {

// "AxB" with both in [lo, hi]; UsageError naming the flag otherwise.
std::pair<int, int> parse_size(const std::string& text, const char* flag, int lo, int hi) {
  int a = 0, b = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &a, &x, &b, &extra) != 3 || (x != 'x' && x != 'X') ||
      a < lo || a > hi || b < lo || b > hi) {
    throw UsageError(std::string(flag) + " " + text + ": expected WxH with both in [" +
                     std::to_string(lo) + ", " + std::to_string(hi) + "] (e.g. 256x256)");
  }
  return {a, b};
}

}  // namespace

void add_slf_flags(CLI::App* cmd, SlfFlags& f, const char* samples_flag) {
  f.samples_flag = samples_flag;
  cmd->add_option(samples_flag, f.samples,
                  "Surface light field: atlas size WxH in texels, the surface samples")
      ->capture_default_str();
  cmd->add_option("--charts", f.charts,
                  "Surface light field: how the atlas cuts the surface: conformal (charts of many "
                  "triangles, LSCM) or per-triangle (at least 8 texels a triangle)")
      ->check(CLI::IsMember(meshes::kAtlasChartsNames.names()))
      ->capture_default_str();
  cmd->add_option("--directions", f.directions,
                  "Surface light field: direction grid ZxW, azimuth x polar cells over the "
                  "sphere, or each texel's hemisphere with --direction-space local (64x32, the SLF "
                  "paper's glossy grid, sharpens glints at 4x the bake "
                  "with the same --spp)")
      ->capture_default_str();
  cmd->add_option("--direction-space", f.direction_space,
                  "Surface light field: what the direction grid holds: the views over the "
                  "sphere (the SLF paper's), their mirror images about the shading normal "
                  "(reflected, Wood et al. 2000: a glossy lobe and what it reflects sit at one "
                  "grid place across the surface), or the views over each texel's hemisphere "
                  "in its own frame (local: no cell below the horizon, twice the polar "
                  "resolution; lower error on a smooth sphere's glints, higher on the bunny's "
                  "and horse's rims, docs/BENCHMARKS.md)")
      ->check(CLI::IsMember(prt::kSlfDirectionSpaceNames.names()))
      ->capture_default_str();
  add_checked_option(cmd, "--spp", f.spp,
                     "Surface light field: path-traced samples per texel and direction cell",
                     integer_in(1, 65536));
  add_checked_option(cmd, "--light-samples", f.light_samples,
                     "Surface light field: probe samples a path's first light sample is made of, "
                     "shared by all of a texel's cells (one shadow ray each; 0: every path its "
                     "own)",
                     integer_in(0, prt::kMaxLightSamples));
  add_checked_option(cmd, "--texel-filter", f.texel_filter,
                     "Surface light field: before compression, smooth each texel with its "
                     "neighbours within this many texels on the same chart and facing within 20 "
                     "degrees (cross-bilateral; trades bake noise for blur; 0: off)",
                     integer_in(0, 8));
}

void resolve_slf_flags(const SlfFlags& f, pipeline::SlfSettings& settings) {
  std::tie(settings.atlas_width, settings.atlas_height) =
      parse_size(f.samples, f.samples_flag, 4, 8192);
  settings.charts = meshes::kAtlasChartsNames.parse(f.charts);
  std::tie(settings.bake.grid.azimuth, settings.bake.grid.elevation) =
      parse_size(f.directions, "--directions", 1, 4096);
  settings.bake.grid.space = prt::kSlfDirectionSpaceNames.parse(f.direction_space);
  settings.bake.spp = f.spp;
  settings.bake.light_samples = f.light_samples;
  settings.filter.radius = f.texel_filter;
}

void check_slf_settings(const pipeline::SlfSettings& settings) {
  if (settings.compress.alpha > 0 || settings.compress.overdraw_reduction)
    throw UsageError(
        "--alpha and --overdraw-reduction need mesh vertices; a surface light field's rows "
        "are atlas texels");
  try {
    settings.bake.validate();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

}  // namespace prtr_app
