// cpca/src/metis_kway.h: the one call into METIS 5 (Karypis & Kumar), a weighted k-way
// partition of a graph in compressed-row form. Both users (super-clusters over the cluster
// graph, patch-first over the mesh) go through it, so METIS is included in one file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace cpca {

struct KwayGraph {
  std::vector<std::uint32_t> offset;  // node n's neighbours: [offset[n], offset[n + 1])
  std::vector<std::uint32_t> neighbor;
  std::vector<std::uint32_t> weight;       // one per neighbor entry
  std::vector<std::uint32_t> node_weight;  // one per node, what parts balance; empty: 1 each
};

struct KwayOptions {
  int parts = 1;
  std::uint64_t seed = 1;
  // Each part's share of the nodes' weight (sums to 1); empty: equal parts.
  std::vector<float> shares;
  // Allowed imbalance in 1/1000 above the share; 0 keeps METIS's default (3%).
  int imbalance = 0;
  std::string nodes = "nodes";  // what the nodes are, for the error message
  std::string advice;           // what to do when METIS fails, appended to the message
};

// Part of every node; std::runtime_error naming the sizes when METIS fails.
std::vector<std::uint32_t> metis_kway(const KwayGraph& graph, const KwayOptions& options);

}  // namespace cpca
