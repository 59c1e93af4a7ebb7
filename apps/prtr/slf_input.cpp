#include "slf_input.h"

#include "commands.h"

#include "meshes/atlas.h"
#include "meshes/load.h"
#include "probes/load.h"
#include "prt/slf_bake.h"
#include "render/slf_from_compressed.h"

#include <fstream>
#include <stdexcept>

namespace prtr_app {

bool is_slfc(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  return in.read(magic, sizeof magic) && std::string(magic, sizeof magic) == "PRTRSLFC";
}

render::SlfModel slf_render_model(const meshes::Mesh& mesh, const pipeline::CompressedSlf& slf) {
  const meshes::Atlas atlas =
      meshes::make_atlas(mesh, slf.bake.atlas_width, slf.bake.atlas_height, {slf.bake.charts});
  return render::slf_model_from_compressed(mesh, atlas, slf.bake.grid, slf.set);
}

SlfInput load_slf_input(const std::string& slfc, const std::string& mesh,
                        const MeshFlags& mesh_flags, const std::string& probe) {
  SlfInput in;
  in.slf = pipeline::read_slfc(slfc);
  const pipeline::CompressedSlf& slf = in.slf;
  if (!slf.complete())
    throw std::runtime_error(slfc + " holds only rows " + std::to_string(slf.bake.first_row) +
                             " to " + std::to_string(slf.bake.first_row + slf.bake.row_count) +
                             " of " + std::to_string(slf.bake.rows) +
                             " (a measurement made with --rows); make it without --rows");
  in.mesh_path = mesh.empty() ? slf.mesh_path : mesh;
  in.mesh = meshes::load_mesh(in.mesh_path, load_options(mesh_flags));
  if (meshes::content_hash(in.mesh) != slf.bake.mesh_hash)
    throw std::runtime_error(slfc + " was made from a different mesh than " + in.mesh_path +
                             " (stale); make it again, or pass the right --mesh (and the "
                             "--crease-angle it was made with)");
  in.probe = probes::load_probe(probe);
  if (prt::probe_hash(in.probe) != slf.bake.probe_hash)
    throw UsageError("--probe: " + slfc + " was baked under " + slf.probe_name + ", not " + probe +
                     "; a surface light field's lighting is fixed, so pass the probe it was "
                     "made with");
  in.model = slf_render_model(in.mesh, slf);
  return in;
}

}  // namespace prtr_app
