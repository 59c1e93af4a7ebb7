// prtr info FILE [--mesh MESH]: describe a transfer file and, given the mesh, say whether
// the bake is stale. (Compressed files join when cpca/ writes them.)
#include "commands.h"

#include "meshes/load.h"
#include "progress_bar.h"
#include "prt/transfer_file.h"

#include <cstdio>
#include <filesystem>
#include <string>

namespace prtr_app {

Runner add_info_command(CLI::App& app) {
  struct Options {
    std::string path, mesh;
    bool verify = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a transfer file (.prtx)");
  cmd->add_option("FILE", opt->path, "Transfer file")->required();
  cmd->add_option("--mesh", opt->mesh, "Check the file against this mesh (stale or current)");
  cmd->add_flag("--verify", opt->verify, "Also read the payload and check its checksum and values");

  return [opt] {
    const prt::TransferSet set =
        opt->verify ? prt::read_transfer(opt->path) : prt::read_transfer_header(opt->path);
    const prt::Material& m = set.material;
    std::printf("file        %s (%s)\n", opt->path.c_str(),
                format_bytes(std::filesystem::file_size(opt->path)).c_str());
    std::printf("transfer    %s, order %d (%d coefficients), %d channel(s)\n",
                prt::transfer_kind_name(set.kind), set.order, set.coefficient_count(),
                set.channels);
    std::printf("vertices    %llu\n", static_cast<unsigned long long>(set.vertex_count));
    std::printf("bake        %d samples, %d bounce(s), seed %llu\n", set.samples, set.bounces,
                static_cast<unsigned long long>(set.seed));
    std::printf(
        "material    %s, albedo (%g, %g, %g), specular %g, exponent %g, roughness %g, "
        "f0 %g\n",
        prt::material_name(m.kind), m.albedo.x(), m.albedo.y(), m.albedo.z(), m.specular,
        m.exponent, m.roughness, m.f0);
    std::printf("mesh hash   %016llx\n", static_cast<unsigned long long>(set.mesh_hash));
    if (opt->verify) std::printf("payload     checksum and values verified\n");
    if (!opt->mesh.empty()) {
      const meshes::Mesh mesh = meshes::load_mesh(opt->mesh);
      const bool current =
          meshes::content_hash(mesh) == set.mesh_hash && mesh.vertex_count() == set.vertex_count;
      std::printf("status      %s against %s\n", current ? "current" : "STALE", opt->mesh.c_str());
      if (!current) {
        throw std::runtime_error(opt->path + " was baked from a different mesh than " + opt->mesh +
                                 "; bake it again with prtr bake");
      }
    }
  };
}

}  // namespace prtr_app
