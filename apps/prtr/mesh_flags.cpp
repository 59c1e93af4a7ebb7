#include "mesh_flags.h"

#include "flag_checks.h"

namespace prtr_app {

void add_mesh_flags(CLI::App* cmd, MeshFlags& flags) {
  cmd->add_option("--crease-angle", flags.crease_angle_deg,
                  "For meshes without normals in the file: edges whose faces meet at more "
                  "than this many degrees stay hard (0: all flat, 180: all smooth; 30 is "
                  "Blender's auto smooth)")
      ->check(number_in(0, 180))
      ->capture_default_str();
}

meshes::LoadOptions load_options(const MeshFlags& flags) {
  meshes::LoadOptions options;
  options.crease_angle_deg = flags.crease_angle_deg;
  return options;
}

}  // namespace prtr_app
