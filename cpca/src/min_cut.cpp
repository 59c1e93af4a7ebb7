#include "cpca/min_cut.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>

namespace cpca {

BinaryLabelling::BinaryLabelling(int nodes)
    : nodes_(nodes),
      cost0_(std::size_t(std::max(nodes, 0)), 0.0),
      cost1_(std::size_t(std::max(nodes, 0)), 0.0) {
  if (nodes < 0) throw std::invalid_argument("BinaryLabelling: negative node count");
}

void BinaryLabelling::add_unary(int x, double cost0, double cost1) {
  if (x < 0 || x >= nodes_ || !std::isfinite(cost0) || !std::isfinite(cost1))
    throw std::invalid_argument("BinaryLabelling::add_unary: node " + std::to_string(x) +
                                " out of range or a cost not finite");
  cost0_[std::size_t(x)] += cost0;
  cost1_[std::size_t(x)] += cost1;
}

void BinaryLabelling::add_potts(int x, int y, double w) {
  if (x < 0 || x >= nodes_ || y < 0 || y >= nodes_ || !(w >= 0) || !std::isfinite(w))
    throw std::invalid_argument("BinaryLabelling::add_potts: nodes " + std::to_string(x) + ", " +
                                std::to_string(y) + " out of range or a weight not finite >= 0");
  if (x != y && w > 0) pairs_.push_back({x, y, w});
}

double BinaryLabelling::energy(const std::vector<std::uint8_t>& labels) const {
  double e = 0;
  for (int x = 0; x < nodes_; ++x)
    e += labels[std::size_t(x)] ? cost1_[std::size_t(x)] : cost0_[std::size_t(x)];
  for (const Pair& p : pairs_)
    if (labels[std::size_t(p.x)] != labels[std::size_t(p.y)]) e += p.w;
  return e;
}

void BinaryLabelling::add_arc_pair(int a, int b, double forward, double backward) {
  out_[std::size_t(a)].push_back(int(arcs_.size()));
  arcs_.push_back({b, forward});
  out_[std::size_t(b)].push_back(int(arcs_.size()));
  arcs_.push_back({a, backward});
}

bool BinaryLabelling::levels(int s, int t) {
  std::fill(level_.begin(), level_.end(), -1);
  std::queue<int> q;
  level_[std::size_t(s)] = 0;
  q.push(s);
  while (!q.empty()) {
    const int x = q.front();
    q.pop();
    for (int a : out_[std::size_t(x)])
      if (arcs_[std::size_t(a)].residual > 0 && level_[std::size_t(arcs_[std::size_t(a)].to)] < 0) {
        level_[std::size_t(arcs_[std::size_t(a)].to)] = level_[std::size_t(x)] + 1;
        q.push(arcs_[std::size_t(a)].to);
      }
  }
  return level_[std::size_t(t)] >= 0;
}

double BinaryLabelling::push(int x, int t, double limit) {
  if (x == t) return limit;
  for (int& i = next_[std::size_t(x)]; i < int(out_[std::size_t(x)].size()); ++i) {
    const int a = out_[std::size_t(x)][std::size_t(i)];
    Arc& arc = arcs_[std::size_t(a)];
    if (arc.residual <= 0 || level_[std::size_t(arc.to)] != level_[std::size_t(x)] + 1) continue;
    const double pushed = push(arc.to, t, std::min(limit, arc.residual));
    if (pushed > 0) {
      arc.residual -= pushed;
      arcs_[std::size_t(a ^ 1)].residual += pushed;
      return pushed;
    }
  }
  return 0;
}

std::vector<std::uint8_t> BinaryLabelling::solve() {
  // Source s: label 0's side. Cutting s -> x (x on the sink side, label 1) pays cost1 - m,
  // cutting x -> t pays cost0 - m, m = min(cost0, cost1): E differs by a constant.
  const int s = nodes_, t = nodes_ + 1;
  arcs_.clear();
  out_.assign(std::size_t(nodes_ + 2), {});
  for (int x = 0; x < nodes_; ++x) {
    const double c0 = cost0_[std::size_t(x)], c1 = cost1_[std::size_t(x)];
    const double m = std::min(c0, c1);
    if (c1 > m) add_arc_pair(s, x, c1 - m, 0);
    if (c0 > m) add_arc_pair(x, t, c0 - m, 0);
  }
  for (const Pair& p : pairs_) add_arc_pair(p.x, p.y, p.w, p.w);
  double scale = 0;
  for (const Arc& a : arcs_) scale = std::max(scale, a.residual);
  level_.assign(std::size_t(nodes_ + 2), -1);
  next_.assign(std::size_t(nodes_ + 2), 0);
  while (levels(s, t)) {
    std::fill(next_.begin(), next_.end(), 0);
    while (push(s, t, std::numeric_limits<double>::infinity()) > 0) {
    }
  }
  // The nodes still reachable from s in the residual graph take label 0 (the least source
  // side, so ties go to label 1). Flows of doubles leave residuals of rounding size: an arc
  // counts as saturated below 1e-12 of the largest capacity.
  std::vector<std::uint8_t> labels(std::size_t(nodes_), 1);
  std::vector<int> stack{s};
  std::vector<std::uint8_t> seen(std::size_t(nodes_ + 2), 0);
  seen[std::size_t(s)] = 1;
  const double tiny = 1e-12 * scale;
  while (!stack.empty()) {
    const int x = stack.back();
    stack.pop_back();
    if (x < nodes_) labels[std::size_t(x)] = 0;
    for (int a : out_[std::size_t(x)]) {
      const Arc& arc = arcs_[std::size_t(a)];
      if (arc.residual > tiny && !seen[std::size_t(arc.to)])
        seen[std::size_t(arc.to)] = 1, stack.push_back(arc.to);
    }
  }
  return labels;
}

}  // namespace cpca
