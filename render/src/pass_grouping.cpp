#include "render/pass_grouping.h"

#include "cpca/supercluster_strategy.h"
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
  const render::ConstantLayout layout = render::constant_layout(set);
  const int budget =
      register_budget > 0 ? register_budget : context.info().default_register_budget();
  int per_pass = budget / layout.registers_per_cluster();
  if (clusters_per_pass > 0) per_pass = std::min(per_pass, clusters_per_pass);
  if (per_pass < 1 || strategy == "order") return std::nullopt;
  const std::vector<cpca::TriangleIndices> triangles(mesh.triangles.begin(), mesh.triangles.end());
  const cpca::SuperClusterInput input{set.cluster_of, triangles, set.cluster_count, per_pass};
  return cpca::group_clusters(strategy, input);
}

}  // namespace render
