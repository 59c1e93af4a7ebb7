// cpca/supercluster_refine.h: local search that lowers the exact triangle overdraw of a
// grouping by moving single clusters into passes with room and by swapping two clusters
// of different passes, keeping every pass within capacity.
//
// Every step is evaluated exactly on the clusters' hyperedges (cpca/supercluster_incidence.h)
// and applied only when it strictly lowers the triangles drawn, so refinement never makes a
// grouping worse and always terminates. Only passes holding a neighbour of a cluster are
// tried for it: moving or swapping a cluster into a pass where none of its triangles'
// other clusters live cannot lower that cluster's draws, and the partner's side of such a
// swap is examined when the partner itself is visited.
#pragma once

#include "cpca/supercluster_incidence.h"

#include <cstdint>
#include <vector>

namespace cpca {

class GroupingLocalSearch {
 public:
  // pass_of: one entry per cluster, each < passes; pass sizes must be <= per_pass.
  GroupingLocalSearch(const ClusterIncidence& incidence, int per_pass,
                      std::vector<std::uint32_t> pass_of, int passes);

  std::uint64_t drawn() const { return drawn_; }
  const std::vector<std::uint32_t>& pass_of() const { return pass_of_; }
  const std::vector<std::uint32_t>& members(std::uint32_t pass) const { return members_[pass]; }
  int pass_count() const { return int(members_.size()); }
  int per_pass() const { return per_pass_; }

  // Change in triangles drawn if cluster c moved to pass q / if c and d traded passes.
  // O(1) from the pull table (plus c's hyperedges shared with d, for a swap).
  std::int64_t delta_move(std::uint32_t c, std::uint32_t q) const;
  std::int64_t delta_swap(std::uint32_t c, std::uint32_t d) const;
  // The slow, obvious references: recount c's (and d's) hyperedges. Tests hold the fast
  // versions to them.
  std::int64_t delta_move_reference(std::uint32_t c, std::uint32_t q) const;
  std::int64_t delta_swap_reference(std::uint32_t c, std::uint32_t d) const;
  // For every neighbour d of c, adds to correction[d] (sized K) the part of delta_swap(c, d)
  // beyond the two single moves, delta_move(c, pass of d) + delta_move(d, pass of c): one walk
  // over c's hyperedges for all its partners, which descend() needs, instead of one a partner.
  void shared_corrections(std::uint32_t c, std::vector<std::int64_t>& correction) const;
  // Apply them (no capacity check beyond an always-on one for moves).
  void move(std::uint32_t c, std::uint32_t q);
  void swap(std::uint32_t c, std::uint32_t d);

  // Best-improvement steps from the clusters in `worklist` (all clusters when empty),
  // re-examining the neighbourhood of every change, until no step improves. Returns the
  // number of steps applied.
  int descend(std::vector<std::uint32_t> worklist = {});
  // Full descend() sweeps until one applies nothing: a true local optimum for moves and
  // swaps. Returns the steps applied.
  int descend_fully();

  // A trial the caller may take back. The moves and swaps made after begin_trial() are
  // journaled; undo_trial() replays them backwards and restores the state exactly, member
  // order included, so a search that goes on is the one it would have been from a copy made
  // before the trial, at the cost of the trial's moves instead of a copy of the K x passes
  // pull table. end_trial() keeps the moves.
  void begin_trial();
  void undo_trial();
  void end_trial();

  // Clusters to re-examine after c changed pass: c, its neighbours (their deltas changed)
  // and the members of its old and new pass (their room and partners changed). Appended to
  // `out`. A cluster elsewhere whose best swap partner is now c is not re-examined, so
  // descend() ends at a local optimum only for a full worklist; refine_grouping() therefore
  // repeats full sweeps until one finds nothing.
  void affected(std::uint32_t c, std::uint32_t old_pass, std::vector<std::uint32_t>& out) const;

  SuperClusters groups() const { return groups_from_pass_of(pass_of_); }

 private:
  const ClusterIncidence* inc_;  // a pointer so that searches can be copied and assigned
  int per_pass_;
  std::vector<std::uint32_t> pass_of_;
  std::vector<std::vector<std::uint32_t>> members_;
  std::uint64_t drawn_ = 0;
  // pull_[c * passes + q]: triangles of c that have another vertex in a cluster of pass q.
  // Cluster c in pass q draws its multi-cluster triangles (constant) - pull(c, q) times
  // fewer, so delta_move(c, q) = pull(c, p) - pull(c, q): the thesis's "overdraw reduced by
  // the clusters already chosen", kept up to date for every pass at once.
  std::vector<std::uint32_t> pull_;
  std::uint32_t& pull(std::uint32_t c, std::uint32_t q) { return pull_[c * members_.size() + q]; }
  std::uint32_t pull(std::uint32_t c, std::uint32_t q) const {
    return pull_[c * members_.size() + q];
  }
  void relocate(std::uint32_t c, std::uint32_t q);  // pass_of_, members_, pull_; not drawn_
  void shift_pulls(std::uint32_t x, std::uint32_t a, std::uint32_t b);  // x from pass a to b
  struct Relocation {
    std::uint32_t cluster, from, index;  // index: its place among `from`'s members
  };
  std::vector<Relocation> journal_;
  bool journaling_ = false;
  std::uint64_t trial_drawn_ = 0;
  std::int64_t shared_correction(std::uint32_t c, std::uint32_t d) const;
};

// Local search from `start` (a grouping of the incidence's clusters); the result is never
// worse than the start and uses at most as many passes.
SuperClusters refine_grouping(const ClusterIncidence& incidence, int per_pass,
                              const SuperClusters& start);

}  // namespace cpca
