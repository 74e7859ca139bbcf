#include "soft_tissue_cutting/collision/aabb_tree.hpp"

#include <algorithm>
#include <limits>

namespace stc {

namespace {
constexpr int kLeafSize = 4;
}

void AabbTree::build(std::vector<Box3> boxes) {
  nodes_.clear();
  order_.resize(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) order_[i] = static_cast<int>(i);
  if (!boxes.empty()) build_node(boxes, 0, static_cast<int>(boxes.size()));
  leaf_of_.assign(boxes.size(), -1);
  parent_.assign(nodes_.size(), -1);
  for (size_t i = 0; i < nodes_.size(); ++i) {
    const Node& node = nodes_[i];
    if (node.left < 0) {
      for (int k = node.first; k < node.first + node.count; ++k)
        leaf_of_[static_cast<size_t>(order_[static_cast<size_t>(k)])] = static_cast<int>(i);
    } else {
      parent_[static_cast<size_t>(node.left)] = parent_[static_cast<size_t>(node.right)] =
          static_cast<int>(i);
    }
  }
  boxes_ = std::move(boxes);
}

int AabbTree::build_node(const std::vector<Box3>& boxes, int first, int count) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Box3 box;
  box.setEmpty();
  for (int k = first; k < first + count; ++k) box.extend(boxes[order_[k]]);
  nodes_[index].box = box;
  if (count <= kLeafSize) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis;
  box.sizes().maxCoeff(&axis);
  const int half = count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + first + half,
                   order_.begin() + first + count,
                   [&](int a, int b) { return boxes[a].center()[axis] < boxes[b].center()[axis]; });
  const int left = build_node(boxes, first, half);
  const int right = build_node(boxes, first + half, count - half);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

void AabbTree::refit(std::vector<Box3> boxes) {
  boxes_ = std::move(boxes);
  refit_nodes(static_cast<int>(nodes_.size()) - 1, 0);
}

void AabbTree::refit(const std::vector<std::pair<int, Box3>>& changed) {
  std::vector<int> dirty;
  for (const auto& [primitive, box] : changed) {
    boxes_[static_cast<size_t>(primitive)] = box;
    for (int i = leaf_of_[static_cast<size_t>(primitive)]; i >= 0;
         i = parent_[static_cast<size_t>(i)])
      dirty.push_back(i);
  }
  std::sort(dirty.begin(), dirty.end());
  dirty.erase(std::unique(dirty.begin(), dirty.end()), dirty.end());
  for (auto it = dirty.rbegin(); it != dirty.rend(); ++it) refit_nodes(*it, *it);
}

void AabbTree::refit_nodes(int from, int to) {
  // Children are created after their parent, so a descending sweep visits children first.
  for (int i = from; i >= to; --i) {
    Node& node = nodes_[static_cast<size_t>(i)];
    node.box.setEmpty();
    if (node.left < 0) {
      for (int k = node.first; k < node.first + node.count; ++k)
        node.box.extend(boxes_[static_cast<size_t>(order_[static_cast<size_t>(k)])]);
    } else {
      node.box.extend(nodes_[static_cast<size_t>(node.left)].box);
      node.box.extend(nodes_[static_cast<size_t>(node.right)].box);
    }
  }
}

void AabbTree::overlapping(const Box3& box, std::vector<int>& out) const {
  if (nodes_.empty()) return;
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    if (!node.box.intersects(box)) continue;
    if (node.left < 0) {
      for (int k = node.first; k < node.first + node.count; ++k) out.push_back(order_[k]);
    } else {
      stack.push_back(node.left);
      stack.push_back(node.right);
    }
  }
}

void AabbTree::along_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                         std::vector<int>& out) const {
  if (nodes_.empty()) return;
  auto hits = [&](const Box3& box) {  // slab test
    double near = 0, far = std::numeric_limits<double>::infinity();
    for (int d = 0; d < 3; ++d) {
      if (dir[d] == 0) {
        if (origin[d] < box.min()[d] || origin[d] > box.max()[d]) return false;
        continue;
      }
      double a = (box.min()[d] - origin[d]) / dir[d], b = (box.max()[d] - origin[d]) / dir[d];
      if (a > b) std::swap(a, b);
      near = std::max(near, a);
      far = std::min(far, b);
      if (near > far) return false;
    }
    return true;
  };
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    if (!hits(node.box)) continue;
    if (node.left < 0) {
      for (int k = node.first; k < node.first + node.count; ++k) out.push_back(order_[k]);
    } else {
      stack.push_back(node.left);
      stack.push_back(node.right);
    }
  }
}

}  // namespace stc
