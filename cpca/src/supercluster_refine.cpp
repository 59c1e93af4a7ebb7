// Exact local search on super-cluster groupings (moves and pairwise swaps); the refinement
// stage the issue asks for after the partitioner, also applied to greedy's result.
#include "cpca/supercluster_refine.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace cpca {

namespace {

// Distinct passes of h when cluster a is in pass pa and b in pb (others from pass_of).
int distinct_with(const ClusterHyperedge& h, const std::vector<std::uint32_t>& pass_of,
                  std::uint32_t a, std::uint32_t pa, std::uint32_t b, std::uint32_t pb) {
  std::uint32_t p[3];
  const int n = h.size();
  for (int i = 0; i < n; ++i) {
    const std::uint32_t k = h.clusters[i];
    p[i] = k == a ? pa : k == b ? pb : pass_of[k];
  }
  if (n == 2) return p[0] == p[1] ? 1 : 2;
  return 1 + int(p[0] != p[1]) + int(p[2] != p[0] && p[2] != p[1]);
}

bool contains(const ClusterHyperedge& h, std::uint32_t k) {
  return h.clusters[0] == k || h.clusters[1] == k || h.clusters[2] == k;
}

}  // namespace

GroupingLocalSearch::GroupingLocalSearch(const ClusterIncidence& incidence, int per_pass,
                                         std::vector<std::uint32_t> pass_of, int passes)
    : inc_(&incidence), per_pass_(per_pass), pass_of_(std::move(pass_of)), members_(passes) {
  if (pass_of_.size() != std::size_t(inc_->cluster_count))
    throw std::logic_error("GroupingLocalSearch: pass_of has " + std::to_string(pass_of_.size()) +
                           " entries for " + std::to_string(inc_->cluster_count) + " clusters");
  for (std::uint32_t k = 0; k < pass_of_.size(); ++k) members_.at(pass_of_[k]).push_back(k);
  for (const auto& m : members_)
    if (int(m.size()) > per_pass_)
      throw std::logic_error("GroupingLocalSearch: a pass holds " + std::to_string(m.size()) +
                             " clusters, capacity " + std::to_string(per_pass_));
  drawn_ = triangles_drawn(*inc_, pass_of_);
}

std::int64_t GroupingLocalSearch::delta_move(std::uint32_t c, std::uint32_t q) const {
  const std::uint32_t p = pass_of_[c];
  std::int64_t delta = 0;
  for (std::uint32_t i = inc_->edge_offset[c]; i < inc_->edge_offset[c + 1]; ++i) {
    const ClusterHyperedge& h = inc_->hyperedges[inc_->edge_index[i]];
    delta += std::int64_t(h.weight) *
             (distinct_with(h, pass_of_, c, q, c, q) - distinct_with(h, pass_of_, c, p, c, p));
  }
  return delta;
}

std::int64_t GroupingLocalSearch::delta_swap(std::uint32_t c, std::uint32_t d) const {
  const std::uint32_t p = pass_of_[c], q = pass_of_[d];
  std::int64_t delta = 0;
  const auto edge_delta = [&](const ClusterHyperedge& h) {
    return std::int64_t(h.weight) *
           (distinct_with(h, pass_of_, c, q, d, p) - distinct_with(h, pass_of_, c, p, d, q));
  };
  for (std::uint32_t i = inc_->edge_offset[c]; i < inc_->edge_offset[c + 1]; ++i)
    delta += edge_delta(inc_->hyperedges[inc_->edge_index[i]]);
  for (std::uint32_t i = inc_->edge_offset[d]; i < inc_->edge_offset[d + 1]; ++i) {
    const ClusterHyperedge& h = inc_->hyperedges[inc_->edge_index[i]];
    if (!contains(h, c)) delta += edge_delta(h);  // shared ones were counted from c's side
  }
  return delta;
}

void GroupingLocalSearch::move(std::uint32_t c, std::uint32_t q) {
  if (int(members_[q].size()) >= per_pass_)
    throw std::logic_error("GroupingLocalSearch::move: pass " + std::to_string(q) + " is full");
  drawn_ = std::uint64_t(std::int64_t(drawn_) + delta_move(c, q));
  auto& from = members_[pass_of_[c]];
  from.erase(std::find(from.begin(), from.end(), c));
  members_[q].push_back(c);
  pass_of_[c] = q;
}

void GroupingLocalSearch::swap(std::uint32_t c, std::uint32_t d) {
  drawn_ = std::uint64_t(std::int64_t(drawn_) + delta_swap(c, d));
  const std::uint32_t p = pass_of_[c], q = pass_of_[d];
  *std::find(members_[p].begin(), members_[p].end(), c) = d;
  *std::find(members_[q].begin(), members_[q].end(), d) = c;
  pass_of_[c] = q;
  pass_of_[d] = p;
}

void GroupingLocalSearch::affected(std::uint32_t c, std::uint32_t old_pass,
                                   std::vector<std::uint32_t>& out) const {
  for (std::uint32_t pass : {old_pass, pass_of_[c]}) {
    for (std::uint32_t m : members_[pass]) {
      out.push_back(m);
      for (std::uint32_t i = inc_->neighbor_offset[m]; i < inc_->neighbor_offset[m + 1]; ++i)
        out.push_back(inc_->neighbor[i]);
    }
  }
  out.push_back(c);
  for (std::uint32_t i = inc_->neighbor_offset[c]; i < inc_->neighbor_offset[c + 1]; ++i)
    out.push_back(inc_->neighbor[i]);
}

int GroupingLocalSearch::descend(std::vector<std::uint32_t> worklist) {
  const std::size_t k_count = pass_of_.size();
  if (worklist.empty())
    for (std::uint32_t k = 0; k < k_count; ++k) worklist.push_back(k);
  std::vector<char> queued(k_count, 0);
  std::vector<std::uint32_t> queue;  // FIFO as a vector with a read head
  for (std::uint32_t k : worklist)
    if (!queued[k]) queued[k] = 1, queue.push_back(k);
  std::vector<std::uint32_t> tried_passes, more;
  int steps = 0;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::uint32_t c = queue[head];
    queued[c] = 0;
    const std::uint32_t p = pass_of_[c];
    tried_passes.clear();
    std::int64_t best = 0;
    std::uint32_t best_pass = 0, best_partner = ClusterHyperedge::kNone;
    bool found = false;
    for (std::uint32_t i = inc_->neighbor_offset[c]; i < inc_->neighbor_offset[c + 1]; ++i) {
      const std::uint32_t q = pass_of_[inc_->neighbor[i]];
      if (q == p || std::find(tried_passes.begin(), tried_passes.end(), q) != tried_passes.end())
        continue;
      tried_passes.push_back(q);
      if (int(members_[q].size()) < per_pass_) {
        const std::int64_t d = delta_move(c, q);
        if (d < best) best = d, best_pass = q, best_partner = ClusterHyperedge::kNone, found = true;
      }
      for (std::uint32_t partner : members_[q]) {
        const std::int64_t d = delta_swap(c, partner);
        if (d < best) best = d, best_pass = q, best_partner = partner, found = true;
      }
    }
    if (!found) continue;
    ++steps;
    more.clear();
    if (best_partner == ClusterHyperedge::kNone) {
      move(c, best_pass);
    } else {
      swap(c, best_partner);
      affected(best_partner, best_pass, more);
    }
    affected(c, p, more);
    for (std::uint32_t k : more)
      if (!queued[k]) queued[k] = 1, queue.push_back(k);
    // Compact the consumed prefix now and then so the queue stays O(K).
    if (head > 4 * k_count) {
      queue.erase(queue.begin(), queue.begin() + std::ptrdiff_t(head + 1));
      head = std::size_t(-1);
    }
  }
  return steps;
}

SuperClusters refine_grouping(const ClusterIncidence& incidence, int per_pass,
                              const SuperClusters& start) {
  GroupingLocalSearch search(incidence, per_pass, start.pass_of, int(start.passes.size()));
  search.descend();
  return search.groups();
}

}  // namespace cpca
