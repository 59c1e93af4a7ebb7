// apps/prtr/mesh_flags.h: --crease-angle, on every command that loads a mesh, so that the
// mesh a bake was made from is loaded the same way by the commands that use the bake (its
// content hash includes the vertices split at creases).
#pragma once

#include "meshes/load.h"

#include <CLI/CLI.hpp>

namespace prtr_app {

struct MeshFlags {
  double crease_angle_deg = meshes::kDefaultCreaseAngleDeg;
};

void add_mesh_flags(CLI::App* cmd, MeshFlags& flags);

meshes::LoadOptions load_options(const MeshFlags& flags);

}  // namespace prtr_app
