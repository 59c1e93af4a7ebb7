// cpca/kd_tree.h: a static 3-D k-d tree for the nearest-point queries of geometry coherence
// (thesis eq. 10: the distance from a vertex to the closest point of a cluster). One tree per
// cluster is rebuilt every clustering iteration, so construction is a single O(n log n) pass
// over flat arrays, and queries take a search radius so that clusters that cannot win are
// rejected after a few nodes.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <vector>

namespace cpca {

class KdTree {
 public:
  KdTree() = default;
  // Points are copied; `ids` (same length) are what queries report and can exclude.
  KdTree(std::vector<Eigen::Vector3f> points, std::vector<std::uint32_t> ids);

  struct Hit {
    std::uint32_t id = kNone;
    float distance = std::numeric_limits<float>::infinity();
  };
  static constexpr std::uint32_t kNone = ~0u;

  // The nearest point strictly closer than `radius`, skipping the point whose id is
  // `exclude`; id kNone when there is none.
  Hit nearest(const Eigen::Vector3f& query, float radius = std::numeric_limits<float>::infinity(),
              std::uint32_t exclude = kNone) const;

  std::size_t size() const { return points_.size(); }

 private:
  struct Node {
    std::uint32_t begin, end;  // point range
    int axis;                  // -1 for a leaf
    float split;
    std::uint32_t left, right;  // child node indices
  };
  std::uint32_t build(std::uint32_t begin, std::uint32_t end);
  void search(std::uint32_t node, const Eigen::Vector3f& q, std::uint32_t exclude, float& best2,
              std::uint32_t& best) const;

  std::vector<Eigen::Vector3f> points_;
  std::vector<std::uint32_t> ids_;
  std::vector<Node> nodes_;
};

}  // namespace cpca
