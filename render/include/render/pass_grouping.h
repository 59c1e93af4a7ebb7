// render/pass_grouping.h: the super-cluster grouping a command hands the multipass and
// decoupled renderers: pass capacity from the register budget (the flag, else what the GL
// context offers) and the shader's per-cluster cost, then the named strategy.
#pragma once

#include "cpca/compressed.h"
#include "cpca/supercluster.h"
#include "meshes/mesh.h"
#include "render/gl_context.h"

#include <optional>
#include <string>

namespace render {

// Empty for "order" (the renderer's own default) or when not even one cluster fits (the
// renderer then reports the budget error). std::invalid_argument for an unknown strategy
// name.
std::optional<cpca::SuperClusters> group_for_renderer(const meshes::Mesh& mesh,
                                                      const cpca::CompressedSet& set,
                                                      const render::GlContext& context,
                                                      int register_budget, int clusters_per_pass,
                                                      const std::string& strategy);

}  // namespace render
