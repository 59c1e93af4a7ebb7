#include "render/pass_capacity.h"

#include <stdexcept>
#include <string>

namespace render {

PassCapacity check_pass_capacity(int registers_per_cluster, int register_budget, int context_budget,
                                 int requested) {
  PassCapacity c;
  c.registers_per_cluster = registers_per_cluster;
  c.register_budget = register_budget > 0 ? register_budget : context_budget;
  if (c.register_budget > context_budget) {
    c.problem = CapacityProblem::kBudgetAboveContext;
  } else if (c.register_budget < c.registers_per_cluster) {
    c.problem = CapacityProblem::kBudgetBelowCluster;
  } else {
    c.clusters_per_pass = c.register_budget / c.registers_per_cluster;
    if (requested > c.clusters_per_pass)
      c.problem = CapacityProblem::kTooManyPerPass;
    else if (requested > 0)
      c.clusters_per_pass = requested;
  }
  return c;
}

PassCapacity pass_capacity(const ConstantLayout& layout, int order, int components,
                           int register_budget, int context_budget, int requested) {
  const PassCapacity c = check_pass_capacity(layout.registers_per_cluster(), register_budget,
                                             context_budget, requested);
  // Messages name the flags, as these numbers come from the command line.
  switch (c.problem) {
    case CapacityProblem::kNone:
      break;
    case CapacityProblem::kBudgetAboveContext:
      throw std::invalid_argument("--register-budget " + std::to_string(c.register_budget) +
                                  " exceeds what the GL context offers (" +
                                  std::to_string(context_budget) + " vec4); lower it");
    case CapacityProblem::kBudgetBelowCluster:
      throw std::invalid_argument(
          "--register-budget " + std::to_string(c.register_budget) + " is below one cluster's " +
          std::to_string(c.registers_per_cluster) + " vec4 (order " + std::to_string(order) + ", " +
          std::to_string(components) + " PCs); raise it or use fewer PCs");
    case CapacityProblem::kTooManyPerPass:
      throw std::invalid_argument("--clusters-per-pass " + std::to_string(requested) + " needs " +
                                  std::to_string(requested * c.registers_per_cluster) +
                                  " vec4 but the budget is " + std::to_string(c.register_budget) +
                                  "; lower it or raise --register-budget");
  }
  return c;
}

PassCapacity pass_capacity(const cpca::CompressedSet& set, int register_budget, int context_budget,
                           int requested) {
  return pass_capacity(constant_layout(set), set.order, set.component_count, register_budget,
                       context_budget, requested);
}

}  // namespace render
