#include "render/pass_capacity.h"

#include <stdexcept>
#include <string>

namespace render {

PassCapacity pass_capacity(const ConstantLayout& layout, int order, int components,
                           int register_budget, int context_budget, int requested) {
  PassCapacity c;
  c.registers_per_cluster = layout.registers_per_cluster();
  c.register_budget = register_budget > 0 ? register_budget : context_budget;
  // Messages name the flags, as these numbers come from the command line.
  if (c.register_budget > context_budget)
    throw std::invalid_argument("--register-budget " + std::to_string(c.register_budget) +
                                " exceeds what the GL context offers (" +
                                std::to_string(context_budget) + " vec4); lower it");
  if (c.register_budget < c.registers_per_cluster)
    throw std::invalid_argument(
        "--register-budget " + std::to_string(c.register_budget) + " is below one cluster's " +
        std::to_string(c.registers_per_cluster) + " vec4 (order " + std::to_string(order) + ", " +
        std::to_string(components) + " PCs); raise it or use fewer PCs");
  c.clusters_per_pass = c.register_budget / c.registers_per_cluster;
  if (requested > 0) {
    if (requested > c.clusters_per_pass)
      throw std::invalid_argument("--clusters-per-pass " + std::to_string(requested) + " needs " +
                                  std::to_string(requested * c.registers_per_cluster) +
                                  " vec4 but the budget is " + std::to_string(c.register_budget) +
                                  "; lower it or raise --register-budget");
    c.clusters_per_pass = requested;
  }
  return c;
}

PassCapacity pass_capacity(const cpca::CompressedSet& set, int register_budget, int context_budget,
                           int requested) {
  return pass_capacity(constant_layout(set), set.order, set.component_count, register_budget,
                       context_budget, requested);
}

}  // namespace render
