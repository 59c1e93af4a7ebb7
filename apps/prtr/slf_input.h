// apps/prtr/slf_input.h: a compressed surface light field (.slfc, pipeline/slf_file.h) as
// the commands that show one load it: the file (complete, not a --rows measurement), the mesh
// it names (or --mesh) and the probe, each checked against the hash the file records, and
// the renderer's model rebuilt from the deterministic atlas.
#pragma once

#include "mesh_flags.h"

#include "meshes/mesh.h"
#include "pipeline/slf_file.h"
#include "probes/probe.h"
#include "render/slf_model.h"

#include <string>

namespace prtr_app {

// A .slfc rather than a mesh or a PRT set: its first bytes say so.
bool is_slfc(const std::string& path);

// The renderer's model of `slf` on `mesh`: the atlas rebuilt as the file records it (size and
// chart method; it is deterministic), then each texel's cluster, weights and view maps.
render::SlfModel slf_render_model(const meshes::Mesh& mesh, const pipeline::CompressedSlf& slf);

struct SlfInput {
  pipeline::CompressedSlf slf;
  std::string mesh_path;  // the mesh loaded: --mesh, or the path the file records
  meshes::Mesh mesh;
  probes::Probe probe;
  render::SlfModel model;
};

// Loads `slfc` and checks it. `mesh` empty: the mesh the file records. A probe other than the
// one it was baked under is a UsageError naming --probe (the lighting is fixed); a stale mesh
// or an incomplete file is a std::runtime_error saying how to make it again.
SlfInput load_slf_input(const std::string& slfc, const std::string& mesh,
                        const MeshFlags& mesh_flags, const std::string& probe);

}  // namespace prtr_app
