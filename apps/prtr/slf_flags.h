// apps/prtr/slf_flags.h: the surface light field's sampling flags (the atlas size, --charts,
// --directions, --direction-space, --spp, --light-samples), registered with one help text and one
// set of defaults by the commands that make an SLF: prtr slf (atlas size as --samples) and prtr
// relight --kind slf (as --slf-samples, since its --samples is the PRT bake's directions per
// vertex).
#pragma once

#include "meshes/atlas.h"
#include "pipeline/slf.h"

#include <CLI/CLI.hpp>

#include <string>

namespace prtr_app {

struct SlfFlags {
  std::string samples = "256x256", directions = "32x16",
              charts = std::string(meshes::kAtlasChartsNames.name(meshes::AtlasCharts::kConformal));
  // Reflected rather than the paper's views: lower image error on every mesh and probe
  // measured (docs/BENCHMARKS.md, "Reflected directions").
  std::string direction_space =
      std::string(prt::kSlfDirectionSpaceNames.name(prt::SlfDirectionSpace::kReflected));
  int spp = 16;
  int light_samples = prt::SlfBakeOptions{}.light_samples;
  int texel_filter = prt::SlfFilterOptions{}.radius;
  const char* samples_flag = "--samples";  // the atlas size's flag name, for messages
};

void add_slf_flags(CLI::App* command, SlfFlags& flags, const char* samples_flag);

// The atlas size and charts, direction grid and spp into `settings`; UsageError naming a malformed
// flag.
void resolve_slf_flags(const SlfFlags& flags, pipeline::SlfSettings& settings);

// UsageErrors for settings a surface light field cannot take: the compression's mesh-vertex
// terms (its rows are atlas texels) and bake settings out of range.
void check_slf_settings(const pipeline::SlfSettings& settings);

}  // namespace prtr_app
