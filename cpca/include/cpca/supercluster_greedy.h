// cpca/supercluster_greedy.h: the thesis's greedy super-cluster selection (thesis §4.3,
// Fig. 4.6 and the worked example of Fig. 4.7).
//
//   1. Seed a pass C with the unassigned cluster that has the most data. The thesis clusters
//      per-vertex PRT vectors, so "data" is vertices: the seed is the unassigned cluster with
//      the most vertices (ties: lower id).
//   2. Add the unassigned cluster that removes the most triangle overdraw given the clusters
//      already in C ("merge" in step 3 means C's reductions accumulate).
//   3. Repeat 2 until C is full, then start a new pass at 1 until every cluster is placed.
//
// "Removes the most overdraw" is exact relative to the thesis's reference point, where every
// unplaced cluster sits in a pass of its own: cluster y joining C saves one draw of every
// triangle that has y and already has a cluster of C, i.e. gain(y) = number of triangles
// containing y and touching C. Ties (including gain 0, when nothing borders C) go to the
// cluster with more vertices, then the lower id.
//
// Cost: gains are updated incrementally from per-cluster hyperedge lists (cpca/
// supercluster_incidence.h), so a pass costs its clusters' boundary triangles plus a scan of
// the unassigned clusters per pick: O(B + K^2) with B boundary hyperedges, never O(K^2 T).
#pragma once

#include "cpca/supercluster_incidence.h"

#include <cstdint>
#include <vector>

namespace cpca {

// The greedy grouping of a validated input.
SuperClusters group_greedy(const SuperClusterInput& input);

// The same on a prepared incidence; `rank` (optional, one entry per cluster) replaces vertex
// count as the seed and tie-break priority (higher first), which the randomised restarts of
// cpca/supercluster_search.h use.
SuperClusters group_greedy(const ClusterIncidence& incidence, int per_pass,
                           const std::vector<std::uint64_t>* rank = nullptr);

}  // namespace cpca
