// cpca/overdraw_bound.h: a lower bound on the overdraw any grouping of a given clustering
// into passes can reach, so a benchmark row shows how far its grouping is from the best one.
//
// What it bounds, precisely: for fixed cluster_of, the minimum over every assignment of
// clusters to passes holding at most `per_pass` clusters each (any number of passes) of
// triangles drawn / triangles. It says nothing about other clusterings.
//
// Why it holds. A triangle spanning clusters {a, b} is drawn once more than needed exactly
// when a and b sit in different passes; one spanning {a, b, c} is drawn 1 extra time when two
// of its three pairs are split and 2 when all three are, so its extra draws are at least half
// its split pairs. Give each 2-cluster triangle weight 2 on its pair and each 3-cluster
// triangle weight 1 on each of its pairs (ClusterIncidence::neighbor_weight): extra draws >=
// (split weight) / 2 = (W - kept weight) / 2, where W is the total pair weight. A cluster
// shares its pass with at most per_pass - 1 others, so the weight kept at cluster c is at most
// the sum of its per_pass - 1 heaviest pair weights, top(c); summing over both ends of every
// kept pair, kept weight <= sum_c top(c) / 2. Hence
//   drawn >= T + ceil((W - sum_c top(c) / 2) / 2) = T + ceil(sum_c (w(c) - top(c)) / 4),
// with w(c) the total pair weight at c. Tight when every cluster's heaviest neighbours can
// share its pass (e.g. a chain of clusters whose heavy pairs are disjoint), which the tests
// check against a brute force over all groupings.
#pragma once

#include "cpca/supercluster_incidence.h"

#include <cstdint>

namespace cpca {

struct GroupingBound {
  std::uint64_t triangles_drawn = 0;  // a lower bound on any grouping's triangles drawn
  double average_overdraw = 1.0;      // triangles_drawn / triangles (1 for no triangles)
};

GroupingBound grouping_overdraw_bound(const ClusterIncidence& incidence, int per_pass);

// The same from the clustering (validated as group_clusters() does).
GroupingBound grouping_overdraw_bound(const SuperClusterInput& input);

}  // namespace cpca
