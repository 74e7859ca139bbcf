#include "soft_tissue_cutting/collision/surface_bvh.hpp"

#include <algorithm>
#include <cmath>

namespace stc {

namespace {

// A displacement per node (empty, or another size than the mesh's: the rest shape) as the
// function place_nodes reads.
auto per_node(const TetMesh& mesh, const std::vector<Vec3>& displacement) {
  const bool with_u = displacement.size() == mesh.nodes.size();
  return
      [&displacement, with_u](size_t v) -> Vec3 { return with_u ? displacement[v] : Vec3::Zero(); };
}

}  // namespace

bool segment_crosses_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                              const Vec3& c, double& s) {
  // Moeller-Trumbore on the segment's direction; barycentrics half-open so a ray through a
  // shared edge is counted by one of its two triangles only (exact ties are measure zero).
  const Vec3 dir = q - p, e1 = b - a, e2 = c - a;
  const Vec3 h = dir.cross(e2);
  const double det = e1.dot(h);
  // Relative, not absolute: a triangle collapsed onto a line or a point (e.g. contact has
  // pulled two of its nodes onto the same blade point, so e1 == e2) has det = 0 only up to
  // rounding, and 1/det of that rounding noise gave arbitrary barycentrics (a "crossing"
  // that depended on the compiler's FMA contraction). A degenerate triangle, or a segment
  // parallel to the plane, has no interior to cross.
  if (std::abs(det) <= 1e-12 * dir.norm() * e1.norm() * e2.norm()) return false;
  const double inv = 1.0 / det;
  const Vec3 w = p - a;
  const double u = w.dot(h) * inv;
  if (u < 0 || u >= 1) return false;
  const Vec3 k = w.cross(e1);
  const double v = dir.dot(k) * inv;
  if (v < 0 || u + v >= 1) return false;
  s = e2.dot(k) * inv;
  return s >= 0 && s <= 1;
}

std::vector<Box3> SurfaceBvh::triangle_boxes(const std::vector<int>& triangles) const {
  std::vector<Box3> boxes;
  boxes.reserve(triangles.size());
  for (int t : triangles) {
    const BoundaryTriangle& tri = surface_.triangles[static_cast<size_t>(t)];
    Box3 box(positions_[tri.nodes[0]]);
    box.extend(positions_[tri.nodes[1]]);
    box.extend(positions_[tri.nodes[2]]);
    boxes.push_back(box);
  }
  return boxes;
}

void SurfaceBvh::build(const TetMesh& mesh, const std::vector<std::uint8_t>& operation_tets,
                       const std::vector<Vec3>& displacement) {
  build(extract_boundary_surface(mesh), mesh, operation_tets, displacement);
}

void SurfaceBvh::build(BoundarySurface surface, const TetMesh& mesh,
                       const std::vector<std::uint8_t>& operation_tets,
                       const std::vector<Vec3>& displacement) {
  surface_ = std::move(surface);
  index_surface(mesh, operation_tets, displacement);
}

void SurfaceBvh::rebuild_after(size_t kept, BoundarySurface tail, const TetMesh& mesh,
                               const std::vector<std::uint8_t>& operation_tets,
                               const std::vector<Vec3>& displacement) {
  // The other tree is exactly triangles 0 .. kept-1 (listed in increasing order) and indexed.
  const bool fits = kept <= surface_.triangles.size() && other_triangles_.size() == kept &&
                    (kept == 0 || other_triangles_.back() == static_cast<int>(kept) - 1) &&
                    other_tree_.size() == static_cast<int>(kept) && other_nodes_.size() == kept;
  surface_.triangles.resize(std::min(kept, surface_.triangles.size()));
  surface_.triangles.insert(surface_.triangles.end(), tail.triangles.begin(), tail.triangles.end());
  surface_.non_manifold_faces = tail.non_manifold_faces;
  bool operation_only = true;
  for (const BoundaryTriangle& t : tail.triangles)
    operation_only = operation_only && (operation_tets.empty() || operation_tets[t.tet]);
  if (!fits || !operation_only) {
    index_surface(mesh, operation_tets, displacement);
    return;
  }
  const size_t n = surface_.triangles.size();
  operation_.assign(n, 1);
  std::fill(operation_.begin(), operation_.begin() + static_cast<std::ptrdiff_t>(kept), 0);
  operation_triangles_.resize(n - kept);
  for (size_t i = kept; i < n; ++i) operation_triangles_[i - kept] = static_cast<int>(i);
  const size_t known = positions_.size();
  const std::vector<int> moved = place_nodes(mesh, per_node(mesh, displacement));
  operation_tree_.build(triangle_boxes(operation_triangles_));
  refit_other_tree(moved, known);
}

void SurfaceBvh::index_surface(const TetMesh& mesh, const std::vector<std::uint8_t>& operation_tets,
                               const std::vector<Vec3>& displacement) {
  operation_.resize(surface_.triangles.size());
  operation_triangles_.clear();
  other_triangles_.clear();
  std::vector<Tri> other_nodes;
  for (size_t i = 0; i < surface_.triangles.size(); ++i) {
    operation_[i] = operation_tets.empty() || operation_tets[surface_.triangles[i].tet];
    (operation_[i] ? operation_triangles_ : other_triangles_).push_back(static_cast<int>(i));
    if (!operation_[i]) other_nodes.push_back(surface_.triangles[i].nodes);
  }
  const size_t known = positions_.size();
  const std::vector<int> moved = place_nodes(mesh, per_node(mesh, displacement));
  operation_tree_.build(triangle_boxes(operation_triangles_));
  // The organ liver: 18.8k triangles, ~2k of them on the operation part; rebuilding the whole
  // tree after each cut cost ~4 ms of its cutting step, refitting all of it ~0.4 ms.
  if (other_nodes == other_nodes_ && other_tree_.size() == static_cast<int>(other_nodes.size())) {
    refit_other_tree(moved, known);
  } else {
    other_tree_.build(triangle_boxes(other_triangles_));
    other_nodes_ = std::move(other_nodes);
    other_start_.assign(mesh.nodes.size() + 1, 0);
    for (const Tri& tri : other_nodes_)
      for (int v : tri) ++other_start_[static_cast<size_t>(v) + 1];
    for (size_t v = 0; v < mesh.nodes.size(); ++v) other_start_[v + 1] += other_start_[v];
    other_of_node_.assign(static_cast<size_t>(other_start_.back()), -1);
    std::vector<int> fill(other_start_.begin(), other_start_.end() - 1);
    for (size_t k = 0; k < other_nodes_.size(); ++k)
      for (int v : other_nodes_[k])
        other_of_node_[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = static_cast<int>(k);
  }
}

template <typename DisplacementOf>
std::vector<int> SurfaceBvh::place_nodes(const TetMesh& mesh, DisplacementOf displacement_of) {
  // One pass: each node's deformed position, compared with the last one in place (copying the
  // whole mesh's positions and comparing them after cost a follow stroke's steps ~0.2 ms).
  const size_t n = mesh.nodes.size(), known = std::min(positions_.size(), n);
  positions_.resize(n);
  std::vector<int> moved;
  for (size_t v = 0; v < n; ++v) {
    const Vec3 p = mesh.nodes[v] + displacement_of(v);
    if (v < known && p == positions_[v]) continue;
    positions_[v] = p;
    if (v < known) moved.push_back(static_cast<int>(v));
  }
  return moved;
}

void SurfaceBvh::refit(const TetMesh& mesh, const std::vector<Vec3>& displacement) {
  refit_placed(mesh, per_node(mesh, displacement));
}

void SurfaceBvh::refit(const TetMesh& mesh, const Eigen::VectorXd& displacement) {
  const bool with_u = displacement.size() == 3 * static_cast<Eigen::Index>(mesh.nodes.size());
  refit_placed(mesh, [&](size_t v) -> Vec3 {
    return with_u ? Vec3(displacement.segment<3>(3 * static_cast<Eigen::Index>(v))) : Vec3::Zero();
  });
}

template <typename DisplacementOf>
void SurfaceBvh::refit_placed(const TetMesh& mesh, DisplacementOf displacement_of) {
  const size_t known = positions_.size();
  const std::vector<int> moved = place_nodes(mesh, displacement_of);
  operation_tree_.refit(triangle_boxes(operation_triangles_));
  refit_other_tree(moved, known);
}

void SurfaceBvh::refit_other_tree(const std::vector<int>& moved_nodes, size_t known) {
  // The other triangles (a `follow` region's condensed surface: 16.8k of the organ liver's
  // 18.8k) keep their places from one step to the next but for the ~100-150 on interface
  // nodes, until the condensed part's displacement is recovered again: only the triangles
  // whose nodes moved are refitted (a step's refit 0.42 -> ~0.15 ms there). Nodes past
  // `known` (those whose last positions were known) are new since: on no other triangle
  // (those are the tree's, from its build).
  const size_t indexed = other_start_.empty() ? 0 : other_start_.size() - 1;
  if (known < indexed) {  // positions unknown for some of the tree's nodes
    other_tree_.refit(triangle_boxes(other_triangles_));
    return;
  }
  // Where most of it moved (a fixed region: its condensed surface moves with every solve), the
  // whole tree is refitted at once: gathering and sorting its triangles first cost a pressing
  // step on the organ liver ~1 ms more than that refit.
  const size_t most = other_nodes_.size() / 4;
  std::vector<int> primitives;  // of the other tree, on a node that moved
  for (int v : moved_nodes) {
    if (static_cast<size_t>(v) >= indexed) continue;
    primitives.insert(primitives.end(), other_of_node_.begin() + other_start_[v],
                      other_of_node_.begin() + other_start_[v + 1]);
    if (primitives.size() > 3 * most) {  // each triangle counted at most three times
      other_tree_.refit(triangle_boxes(other_triangles_));
      return;
    }
  }
  std::sort(primitives.begin(), primitives.end());
  primitives.erase(std::unique(primitives.begin(), primitives.end()), primitives.end());
  std::vector<std::pair<int, Box3>> moved;
  for (int k : primitives) {
    const Tri& nodes = other_nodes_[static_cast<size_t>(k)];
    Box3 box(positions_[static_cast<size_t>(nodes[0])]);
    box.extend(positions_[static_cast<size_t>(nodes[1])]);
    box.extend(positions_[static_cast<size_t>(nodes[2])]);
    moved.emplace_back(k, box);
  }
  if (moved.size() > most)
    other_tree_.refit(triangle_boxes(other_triangles_));
  else if (!moved.empty())
    other_tree_.refit(moved);
}

std::vector<int> SurfaceBvh::near_segment(const Vec3& a, const Vec3& b, double margin) const {
  Box3 box(a);
  box.extend(b);
  box.min().array() -= margin;
  box.max().array() += margin;
  std::vector<int> found, other;
  operation_tree_.overlapping(box, found);
  other_tree_.overlapping(box, other);
  for (int& k : found) k = operation_triangles_[static_cast<size_t>(k)];
  for (int k : other) found.push_back(other_triangles_[static_cast<size_t>(k)]);
  return found;
}

bool SurfaceBvh::contains(const Vec3& p) const {
  // A direction no structured mesh lines up with, so ties with edges are vanishingly rare.
  const Vec3 dir = Vec3(0.5773502691896258, 0.5773502691896257, 0.5773502691896259).normalized() +
                   Vec3(1.3e-3, -2.9e-3, 0.7e-3);
  std::vector<int> candidates, other;
  operation_tree_.along_ray(p, dir, candidates);
  other_tree_.along_ray(p, dir, other);
  for (int& k : candidates) k = operation_triangles_[static_cast<size_t>(k)];
  for (int k : other) candidates.push_back(other_triangles_[static_cast<size_t>(k)]);
  // Segment long enough to leave every box: the ray is clipped by the scene's extent.
  double extent = 0;
  for (int t : candidates)
    for (int v : surface_.triangles[t].nodes) extent = std::max(extent, (positions_[v] - p).norm());
  const Vec3 far = p + 2 * (extent + 1) * dir;
  int crossings = 0;
  for (int t : candidates) {
    const Tri& n = surface_.triangles[t].nodes;
    double s;
    crossings +=
        segment_crosses_triangle(p, far, positions_[n[0]], positions_[n[1]], positions_[n[2]], s);
  }
  return crossings % 2 == 1;
}

}  // namespace stc
