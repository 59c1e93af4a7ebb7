// Exact local search on super-cluster groupings (moves and pairwise swaps); the refinement
// stage that follows the partitioner, also applied to greedy's result.
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
  pull_.assign(pass_of_.size() * members_.size(), 0);
  for (const ClusterHyperedge& h : inc_->hyperedges) {
    const int n = h.size();
    for (int j = 0; j < n; ++j) {
      std::uint32_t seen[2];
      int count = 0;
      for (int l = 0; l < n; ++l) {
        if (l == j) continue;
        const std::uint32_t q = pass_of_[h.clusters[l]];
        if (std::find(seen, seen + count, q) == seen + count) seen[count++] = q;
      }
      for (int l = 0; l < count; ++l) pull(h.clusters[j], seen[l]) += h.weight;
    }
  }
}

std::int64_t GroupingLocalSearch::delta_move_reference(std::uint32_t c, std::uint32_t q) const {
  const std::uint32_t p = pass_of_[c];
  std::int64_t delta = 0;
  for (std::uint32_t i = inc_->edge_offset[c]; i < inc_->edge_offset[c + 1]; ++i) {
    const ClusterHyperedge& h = inc_->hyperedges[inc_->edge_index[i]];
    delta += std::int64_t(h.weight) *
             (distinct_with(h, pass_of_, c, q, c, q) - distinct_with(h, pass_of_, c, p, c, p));
  }
  return delta;
}

std::int64_t GroupingLocalSearch::delta_swap_reference(std::uint32_t c, std::uint32_t d) const {
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

std::int64_t GroupingLocalSearch::delta_move(std::uint32_t c, std::uint32_t q) const {
  return std::int64_t(pull(c, pass_of_[c])) - std::int64_t(pull(c, q));
}

// A swap is the two single moves plus, on hyperedges holding both c and d, the difference
// between the joint change and the two single-move changes (each single move assumed the
// other cluster stayed put).
std::int64_t GroupingLocalSearch::shared_correction(std::uint32_t c, std::uint32_t d) const {
  const std::uint32_t p = pass_of_[c], q = pass_of_[d];
  std::int64_t correction = 0;
  for (std::uint32_t i = inc_->edge_offset[c]; i < inc_->edge_offset[c + 1]; ++i) {
    const ClusterHyperedge& h = inc_->hyperedges[inc_->edge_index[i]];
    if (!contains(h, d)) continue;
    const int now = distinct_with(h, pass_of_, c, p, d, q);
    const int swapped = distinct_with(h, pass_of_, c, q, d, p);
    const int c_moved = distinct_with(h, pass_of_, c, q, d, q);
    const int d_moved = distinct_with(h, pass_of_, c, p, d, p);
    correction += std::int64_t(h.weight) * ((swapped - now) - (c_moved - now) - (d_moved - now));
  }
  return correction;
}

void GroupingLocalSearch::shared_corrections(std::uint32_t c,
                                             std::vector<std::int64_t>& correction) const {
  // shared_correction's four counts in closed form. Trading c's and d's passes leaves the set
  // of passes on a hyperedge holding both unchanged, so the correction is
  // 2 * now - (c moved to q) - (d moved to p), with the third cluster's pass (if any) fixed.
  const std::uint32_t p = pass_of_[c];
  for (std::uint32_t i = inc_->edge_offset[c]; i < inc_->edge_offset[c + 1]; ++i) {
    const ClusterHyperedge& h = inc_->hyperedges[inc_->edge_index[i]];
    const std::int64_t w = h.weight;
    if (h.size() == 2) {
      const std::uint32_t d = h.clusters[0] == c ? h.clusters[1] : h.clusters[0];
      correction[d] += 2 * w * std::int64_t(pass_of_[d] != p);
      continue;
    }
    const int k = h.clusters[0] == c ? 0 : h.clusters[1] == c ? 1 : 2;
    for (int j = 0; j < 3; ++j) {
      const std::uint32_t d = h.clusters[j];
      if (j == k) continue;
      const std::uint32_t q = pass_of_[d], r = pass_of_[h.clusters[3 - j - k]];
      const int now = 1 + int(p != q) + int(r != p && r != q);
      correction[d] += w * (2 * now - 2 - int(r != q) - int(r != p));
    }
  }
}

std::int64_t GroupingLocalSearch::delta_swap(std::uint32_t c, std::uint32_t d) const {
  const std::uint32_t p = pass_of_[c], q = pass_of_[d];
  return std::int64_t(pull(c, p)) - std::int64_t(pull(c, q)) + std::int64_t(pull(d, q)) -
         std::int64_t(pull(d, p)) + shared_correction(c, d);
}

void GroupingLocalSearch::shift_pulls(std::uint32_t x, std::uint32_t a, std::uint32_t b) {
  // For every other cluster y of x's hyperedges, pass a stops and pass b starts pulling y
  // through x, unless the hyperedge's third cluster already pulls from that pass. The same
  // call with a and b exchanged undoes it while the other clusters stay where they are.
  for (std::uint32_t i = inc_->edge_offset[x]; i < inc_->edge_offset[x + 1]; ++i) {
    const ClusterHyperedge& h = inc_->hyperedges[inc_->edge_index[i]];
    const int n = h.size();
    for (int j = 0; j < n; ++j) {
      const std::uint32_t y = h.clusters[j];
      if (y == x) continue;
      std::uint32_t third_pass = ClusterHyperedge::kNone;
      for (int l = 0; l < n; ++l)
        if (h.clusters[l] != x && h.clusters[l] != y) third_pass = pass_of_[h.clusters[l]];
      if (third_pass != a) pull(y, a) -= h.weight;
      if (third_pass != b) pull(y, b) += h.weight;
    }
  }
}

void GroupingLocalSearch::relocate(std::uint32_t x, std::uint32_t b) {
  const std::uint32_t a = pass_of_[x];
  if (a == b) return;
  shift_pulls(x, a, b);
  auto& from = members_[a];
  const auto at = std::find(from.begin(), from.end(), x);
  if (journaling_) journal_.push_back({x, a, std::uint32_t(at - from.begin())});
  from.erase(at);
  members_[b].push_back(x);
  pass_of_[x] = b;
}

void GroupingLocalSearch::begin_trial() {
  journal_.clear();
  journaling_ = true;
  trial_drawn_ = drawn_;
}

void GroupingLocalSearch::undo_trial() {
  if (!journaling_) throw std::logic_error("GroupingLocalSearch::undo_trial: no trial begun");
  // Backwards, each relocation finds the state it left: its cluster last in its new pass.
  for (auto r = journal_.rbegin(); r != journal_.rend(); ++r) {
    const std::uint32_t b = pass_of_[r->cluster];
    shift_pulls(r->cluster, b, r->from);
    members_[b].pop_back();
    members_[r->from].insert(members_[r->from].begin() + r->index, r->cluster);
    pass_of_[r->cluster] = r->from;
  }
  drawn_ = trial_drawn_;
  end_trial();
}

void GroupingLocalSearch::end_trial() {
  journal_.clear();
  journaling_ = false;
}

void GroupingLocalSearch::move(std::uint32_t c, std::uint32_t q) {
  if (int(members_[q].size()) >= per_pass_)
    throw std::logic_error("GroupingLocalSearch::move: pass " + std::to_string(q) + " is full");
  drawn_ = std::uint64_t(std::int64_t(drawn_) + delta_move(c, q));
  relocate(c, q);
}

void GroupingLocalSearch::swap(std::uint32_t c, std::uint32_t d) {
  drawn_ = std::uint64_t(std::int64_t(drawn_) + delta_swap(c, d));
  const std::uint32_t p = pass_of_[c], q = pass_of_[d];
  relocate(c, q);
  relocate(d, p);
}

void GroupingLocalSearch::affected(std::uint32_t c, std::uint32_t old_pass,
                                   std::vector<std::uint32_t>& out) const {
  for (std::uint32_t pass : {old_pass, pass_of_[c]})
    for (std::uint32_t m : members_[pass]) out.push_back(m);
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
  // shared_correction(c, d) for every neighbour d of the cluster being examined, from one
  // walk over c's hyperedges: per partner it would walk them all again (a fifth of the
  // fallback search's time on a mesh whose clusters are scattered).
  std::vector<std::int64_t> correction(k_count, 0);
  int steps = 0;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::uint32_t c = queue[head];
    queued[c] = 0;
    const std::uint32_t p = pass_of_[c];
    tried_passes.clear();
    std::int64_t best = 0;
    std::uint32_t best_pass = 0, best_partner = ClusterHyperedge::kNone;
    bool found = false;
    const std::uint32_t first = inc_->neighbor_offset[c], last = inc_->neighbor_offset[c + 1];
    shared_corrections(c, correction);
    const std::int64_t pull_here = pull(c, p);
    for (std::uint32_t i = first; i < last; ++i) {
      const std::uint32_t q = pass_of_[inc_->neighbor[i]];
      if (q == p || std::find(tried_passes.begin(), tried_passes.end(), q) != tried_passes.end())
        continue;
      tried_passes.push_back(q);
      if (int(members_[q].size()) < per_pass_) {
        const std::int64_t d = delta_move(c, q);
        if (d < best) best = d, best_pass = q, best_partner = ClusterHyperedge::kNone, found = true;
      }
      // delta_swap inlined: only neighbours can share hyperedges with c.
      const std::int64_t c_part = pull_here - std::int64_t(pull(c, q));
      for (std::uint32_t partner : members_[q]) {
        std::int64_t d = c_part + std::int64_t(pull(partner, q)) - std::int64_t(pull(partner, p));
        d += correction[partner];
        if (d < best) best = d, best_pass = q, best_partner = partner, found = true;
      }
    }
    for (std::uint32_t i = first; i < last; ++i) correction[inc_->neighbor[i]] = 0;
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

int GroupingLocalSearch::descend_fully() {
  int total = 0;
  for (int steps = descend(); steps > 0; steps = descend()) total += steps;
  return total;
}

SuperClusters refine_grouping(const ClusterIncidence& incidence, int per_pass,
                              const SuperClusters& start) {
  GroupingLocalSearch search(incidence, per_pass, start.pass_of, int(start.passes.size()));
  search.descend_fully();
  return search.groups();
}

}  // namespace cpca
