// render/pass_capacity.h: how many clusters one render pass holds. The one place that turns a
// register budget, the SH order and the PCs into clusters per pass (the cost of a cluster is
// ConstantLayout::registers_per_cluster, render/shading.h); the renderer, the grouping for
// it, the overdraw benchmark and the viewer's request parser all ask here.
//
// The rule, decided once: refuse, never clamp. A budget below one cluster's cost, a budget
// above what the GL context offers, or a requested clusters-per-pass count the budget cannot
// hold is a std::invalid_argument naming the flag and the fix, so a command never silently
// renders with other passes than the user asked for.
#pragma once

#include "cpca/compressed.h"
#include "render/shading.h"

namespace render {

// Which limit a budget or count breaks, for callers that phrase the refusal in their own
// words (the viewer's page names query parameters, not flags).
enum class CapacityProblem { kNone, kBudgetAboveContext, kBudgetBelowCluster, kTooManyPerPass };

struct PassCapacity {
  int register_budget = 0;        // vec4 per pass, as resolved (0 in: the context's)
  int registers_per_cluster = 0;  // vec4 one cluster's constants take
  // floor(budget / cost), or the requested count when it fits (with kTooManyPerPass, what
  // would fit)
  int clusters_per_pass = 0;
  CapacityProblem problem = CapacityProblem::kNone;
};

// The rule without the refusal: never throws, `problem` says what is wrong.
PassCapacity check_pass_capacity(int registers_per_cluster, int register_budget, int context_budget,
                                 int requested = 0);

// `register_budget` 0 takes `context_budget`; `requested` 0 takes all that fit.
PassCapacity pass_capacity(const ConstantLayout& layout, int order, int components,
                           int register_budget, int context_budget, int requested = 0);
// The same for a compressed set's layout, order and PCs.
PassCapacity pass_capacity(const cpca::CompressedSet& set, int register_budget, int context_budget,
                           int requested = 0);

}  // namespace render
