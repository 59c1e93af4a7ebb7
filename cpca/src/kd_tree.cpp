#include "cpca/kd_tree.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace cpca {
namespace {
constexpr std::uint32_t kLeafSize = 8;
}

KdTree::KdTree(std::vector<Eigen::Vector3f> points, std::vector<std::uint32_t> ids)
    : points_(std::move(points)), ids_(std::move(ids)) {
  if (points_.size() != ids_.size())
    throw std::invalid_argument("KdTree: points and ids differ in length");
  if (!points_.empty()) {
    nodes_.reserve(2 * points_.size() / kLeafSize + 2);
    build(0, std::uint32_t(points_.size()));
  }
}

std::uint32_t KdTree::build(std::uint32_t begin, std::uint32_t end) {
  const std::uint32_t index = std::uint32_t(nodes_.size());
  nodes_.push_back({begin, end, -1, 0.f, 0, 0});
  if (end - begin <= kLeafSize) return index;
  Eigen::Vector3f lo = points_[begin], hi = points_[begin];
  for (std::uint32_t i = begin + 1; i < end; ++i) {
    lo = lo.cwiseMin(points_[i]);
    hi = hi.cwiseMax(points_[i]);
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  if (!(hi[axis] > lo[axis])) return index;  // all points coincide: keep one leaf
  // Sort a permutation so points and ids move together.
  const std::uint32_t mid = begin + (end - begin) / 2;
  std::vector<std::uint32_t> order(end - begin);
  std::iota(order.begin(), order.end(), begin);
  std::nth_element(
      order.begin(), order.begin() + (mid - begin), order.end(),
      [&](std::uint32_t a, std::uint32_t b) { return points_[a][axis] < points_[b][axis]; });
  std::vector<Eigen::Vector3f> p(order.size());
  std::vector<std::uint32_t> id(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    p[i] = points_[order[i]];
    id[i] = ids_[order[i]];
  }
  std::copy(p.begin(), p.end(), points_.begin() + begin);
  std::copy(id.begin(), id.end(), ids_.begin() + begin);
  const float split = points_[mid][axis];
  const std::uint32_t left = build(begin, mid);
  const std::uint32_t right = build(mid, end);
  Node& n = nodes_[index];
  n.axis = axis;
  n.split = split;
  n.left = left;
  n.right = right;
  return index;
}

void KdTree::search(std::uint32_t node, const Eigen::Vector3f& q, std::uint32_t exclude,
                    float& best2, std::uint32_t& best) const {
  const Node& n = nodes_[node];
  if (n.axis < 0) {
    for (std::uint32_t i = n.begin; i < n.end; ++i) {
      if (ids_[i] == exclude) continue;
      const float d2 = (points_[i] - q).squaredNorm();
      if (d2 < best2) {
        best2 = d2;
        best = i;
      }
    }
    return;
  }
  const float delta = q[n.axis] - n.split;
  const std::uint32_t near = delta < 0 ? n.left : n.right;
  const std::uint32_t far = delta < 0 ? n.right : n.left;
  search(near, q, exclude, best2, best);
  if (delta * delta < best2) search(far, q, exclude, best2, best);
}

KdTree::Hit KdTree::nearest(const Eigen::Vector3f& query, float radius,
                            std::uint32_t exclude) const {
  Hit hit;
  if (nodes_.empty()) return hit;
  float best2 = radius * radius;
  std::uint32_t best = kNone;
  search(0, query, exclude, best2, best);
  if (best != kNone) {
    hit.id = ids_[best];
    hit.distance = std::sqrt(best2);
  }
  return hit;
}

}  // namespace cpca
