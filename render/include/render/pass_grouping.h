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

// Empty for "order" (the renderer's own default). std::invalid_argument for an unknown
// strategy name, and for a budget or clusters-per-pass count that does not fit (the rule of
// render/pass_capacity.h, the renderer's own).
std::optional<cpca::SuperClusters> group_for_renderer(const meshes::Mesh& mesh,
                                                      const cpca::CompressedSet& set,
                                                      const render::GlContext& context,
                                                      int register_budget, int clusters_per_pass,
                                                      const std::string& strategy);

}  // namespace render
