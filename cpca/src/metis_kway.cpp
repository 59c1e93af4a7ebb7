#include "metis_kway.h"

#include <metis.h>

#include <stdexcept>

namespace cpca {

std::vector<std::uint32_t> metis_kway(const KwayGraph& graph, const KwayOptions& options) {
  idx_t nodes = idx_t(graph.offset.size()) - 1, constraints = 1, parts = options.parts, cut = 0;
  std::vector<idx_t> xadj(graph.offset.begin(), graph.offset.end());
  // METIS reads adjncy[0] even for a graph without edges; never hand it an empty buffer.
  std::vector<idx_t> adjncy(graph.neighbor.begin(), graph.neighbor.end());
  std::vector<idx_t> adjwgt(graph.weight.begin(), graph.weight.end());
  adjncy.push_back(0);
  adjwgt.push_back(0);
  std::vector<idx_t> vwgt(graph.node_weight.begin(), graph.node_weight.end());
  std::vector<real_t> shares(options.shares.begin(), options.shares.end());
  std::vector<idx_t> part(std::size_t(nodes), 0);
  idx_t metis_options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(metis_options);
  metis_options[METIS_OPTION_NUMBERING] = 0;
  metis_options[METIS_OPTION_SEED] = idx_t(options.seed & 0x7fffffff);
  if (options.imbalance > 0) metis_options[METIS_OPTION_UFACTOR] = options.imbalance;
  const int rc = METIS_PartGraphKway(&nodes, &constraints, xadj.data(), adjncy.data(),
                                     vwgt.empty() ? nullptr : vwgt.data(), nullptr, adjwgt.data(),
                                     &parts, shares.empty() ? nullptr : shares.data(), nullptr,
                                     metis_options, &cut, part.data());
  if (rc != METIS_OK)
    throw std::runtime_error("METIS_PartGraphKway failed (code " + std::to_string(rc) + ") on " +
                             std::to_string(nodes) + " " + options.nodes + " into " +
                             std::to_string(options.parts) + " parts" +
                             (options.advice.empty() ? "" : "; " + options.advice));
  return std::vector<std::uint32_t>(part.begin(), part.end());
}

}  // namespace cpca
