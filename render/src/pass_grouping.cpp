#include "render/pass_grouping.h"

#include "cpca/supercluster_strategy.h"
#include "render/pass_capacity.h"
#include "render/shading.h"

#include <algorithm>
#include <vector>

namespace render {

std::optional<cpca::SuperClusters> group_for_renderer(const meshes::Mesh& mesh,
                                                      const cpca::CompressedSet& set,
                                                      const render::GlContext& context,
                                                      int register_budget, int clusters_per_pass,
                                                      const std::string& strategy) {
  cpca::find_supercluster_strategy(strategy);  // std::invalid_argument for an unknown name
  const int per_pass = pass_capacity(set, register_budget, context.info().default_register_budget(),
                                     clusters_per_pass)
                           .clusters_per_pass;
  if (strategy == "order") return std::nullopt;
  const std::vector<cpca::TriangleIndices> triangles(mesh.triangles.begin(), mesh.triangles.end());
  const cpca::SuperClusterInput input{set.cluster_of, triangles, set.cluster_count, per_pass};
  return cpca::group_clusters(strategy, input);
}

}  // namespace render
