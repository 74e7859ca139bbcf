// A bounding-volume hierarchy of axis-aligned boxes over any primitives (here: surface
// triangles at their deformed positions). Built top-down by median split on the longest
// axis; refit() updates the boxes bottom-up when the primitives move without changing
// topology (every step), build() again when they change (after a cut).
#pragma once

#include <Eigen/Geometry>

#include <vector>

namespace stc {

using Box3 = Eigen::AlignedBox3d;

class AabbTree {
 public:
  void build(std::vector<Box3> primitive_boxes);
  // Same primitives, new boxes (same order as build).
  void refit(std::vector<Box3> primitive_boxes);
  // Same primitives, new boxes for a few of them (primitive index, box): only their leaves and
  // those leaves' ancestors are refitted; the same tree as refit() with every box.
  void refit(const std::vector<std::pair<int, Box3>>& changed);
  // Primitives whose box overlaps `box` (appended to out, unordered).
  void overlapping(const Box3& box, std::vector<int>& out) const;
  // Primitives whose box the ray origin + s dir, s >= 0, meets.
  void along_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                 std::vector<int>& out) const;
  int size() const { return static_cast<int>(order_.size()); }

 private:
  struct Node {
    Box3 box;
    int left = -1, right = -1;  // children; -1 for a leaf
    int first = 0, count = 0;   // leaf: order_[first, first + count)
  };
  int build_node(const std::vector<Box3>& boxes, int first, int count);
  // Recomputes the boxes of nodes from, from - 1, ..., to (a node's children come after it).
  void refit_nodes(int from, int to);
  std::vector<Node> nodes_;
  std::vector<int> order_;
  std::vector<Box3> boxes_;   // per primitive, as last built or refitted
  std::vector<int> leaf_of_;  // per primitive: its leaf node
  std::vector<int> parent_;   // per node, -1 for the root
};

}  // namespace stc
