// Multi-start iterated local search on the exact overdraw. See cpca/supercluster_search.h.
#include "cpca/supercluster_search.h"

#include "cpca/supercluster_greedy.h"
#include "cpca/supercluster_metis.h"
#include "cpca/supercluster_refine.h"

#include <random>
#include <vector>

namespace cpca {

namespace {

GroupingLocalSearch descended(const ClusterIncidence& inc, int per_pass, int passes,
                              const SuperClusters& start) {
  GroupingLocalSearch search(inc, per_pass, start.pass_of, passes);
  search.descend_fully();
  return search;
}

}  // namespace

SuperClusters group_search(const ClusterIncidence& inc, int per_pass,
                           const SearchOptions& options) {
  const int k_count = inc.cluster_count;
  const int passes = (k_count + per_pass - 1) / per_pass;
  if (passes == 1 || per_pass == 1) return group_greedy(inc, per_pass);

  std::mt19937_64 rng(options.seed);
  GroupingLocalSearch best = descended(inc, per_pass, passes, group_greedy(inc, per_pass));
  const auto consider = [&](const SuperClusters& start) {
    GroupingLocalSearch s = descended(inc, per_pass, passes, start);
    if (s.drawn() < best.drawn()) best = std::move(s);
  };
  consider(group_metis(inc, per_pass, {}));
  for (int r = 0; r < options.random_starts; ++r) {
    std::vector<std::uint64_t> rank(static_cast<std::size_t>(k_count));
    for (auto& x : rank) x = rng();
    consider(group_greedy(inc, per_pass, &rank));
  }

  // Starts may have fewer passes than `passes` (empty ones dropped); ILS works on a fixed
  // pass count, so pad back with empty passes it may refill.
  GroupingLocalSearch current(inc, per_pass, best.pass_of(), passes);
  GroupingLocalSearch best_found = current;
  const long iterations = long(options.kicks_per_cluster) * k_count;
  std::vector<std::uint32_t> touched;
  // Each trial runs on `current` itself and is taken back when it draws more: a copy of the
  // search per iteration (its K x passes pull table, a member list per pass), K x 20 times,
  // cost more than most trials' moves.
  for (long it = 0; it < iterations; ++it) {
    const std::uint64_t before = current.drawn();
    current.begin_trial();
    touched.clear();
    const int kicks = 1 + int(rng() % 3);
    for (int kick = 0; kick < kicks; ++kick) {
      const std::uint32_t c = std::uint32_t(rng() % std::uint64_t(k_count));
      const std::uint32_t from = current.pass_of()[c];
      const std::uint32_t lo = inc.neighbor_offset[c], hi = inc.neighbor_offset[c + 1];
      if (lo == hi) continue;
      const std::uint32_t to = current.pass_of()[inc.neighbor[lo + rng() % (hi - lo)]];
      if (to == from) continue;
      const auto& there = current.members(to);
      const std::size_t pick = rng() % (there.size() + 1);
      if (pick == there.size()) {
        if (int(there.size()) >= per_pass) continue;
        current.move(c, to);
      } else {
        const std::uint32_t d = there[pick];
        current.swap(c, d);
        current.affected(d, to, touched);
      }
      current.affected(c, from, touched);
    }
    if (touched.empty()) {
      current.end_trial();
      continue;
    }
    current.descend(touched);
    if (current.drawn() <= before) {
      current.end_trial();
      if (current.drawn() < best_found.drawn()) best_found = current;
    } else {
      current.undo_trial();
    }
  }
  best_found.descend_fully();  // the cheap worklist descents may stop short of an optimum
  return best_found.groups();
}

SuperClusters group_search(const SuperClusterInput& input) {
  return group_search(cluster_incidence(input), input.per_pass);
}

}  // namespace cpca
