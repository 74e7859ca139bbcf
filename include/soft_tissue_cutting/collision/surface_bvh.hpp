// The tissue's current boundary surface at its DEFORMED positions (rest + displacement), in
// an AABB tree: what the blade is tested against every step. Triangles owned by operation-part
// tets are the ones the blade can touch (edge_contact.hpp, tip_contact.hpp); the whole closed
// surface answers point-in-tissue queries by ray parity. Two trees: the operation part's
// triangles, rebuilt after every cut, and the rest, which a cut never changes (it stops one
// element layer before the interface): kept across cuts and only refitted.
#pragma once

#include "soft_tissue_cutting/collision/aabb_tree.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <cstdint>
#include <vector>

namespace stc {

class SurfaceBvh {
 public:
  // After every cut (the surface changed). operation_tets: per tet, nonzero = operation part
  // (empty = all). displacement: per node (empty = rest shape). The tree of the other
  // triangles is rebuilt only when they changed (a new partition, a new mesh).
  void build(const TetMesh& mesh, const std::vector<std::uint8_t>& operation_tets,
             const std::vector<Vec3>& displacement);
  // The same from a boundary surface the caller already has (e.g. updated from the operation
  // part alone after a cut, simulation/operation_surface.hpp).
  void build(BoundarySurface surface, const TetMesh& mesh,
             const std::vector<std::uint8_t>& operation_tets,
             const std::vector<Vec3>& displacement);
  // After a cut that changed the operation part alone: the first `kept` triangles stay as
  // the last build had them (the other tree's: the caller knows they did not change, e.g.
  // OperationSurface's part-2 triangles of the same extraction), the rest become `tail`'s
  // (its non_manifold_faces: the whole surface's). Neither the kept triangles are copied nor
  // the other tree compared (~0.4 ms a cut on the organ liver's 16.8k); where the kept ones
  // are not exactly the other tree's, or a tail triangle is not the operation part's, the
  // whole surface is indexed as build does.
  void rebuild_after(size_t kept, BoundarySurface tail, const TetMesh& mesh,
                     const std::vector<std::uint8_t>& operation_tets,
                     const std::vector<Vec3>& displacement);
  // Every step (same surface, nodes moved).
  void refit(const TetMesh& mesh, const std::vector<Vec3>& displacement);
  // The same from the displacement as one vector, 3 per node (empty = rest shape).
  void refit(const TetMesh& mesh, const Eigen::VectorXd& displacement);

  const BoundarySurface& surface() const { return surface_; }
  bool is_operation(int triangle) const { return operation_[triangle] != 0; }
  const Vec3& position(int node) const { return positions_[node]; }  // deformed

  // Triangles whose box comes within `margin` of segment [a, b]'s box (candidates).
  std::vector<int> near_segment(const Vec3& a, const Vec3& b, double margin) const;
  // Is p inside the tissue? Ray parity over the whole closed surface.
  bool contains(const Vec3& p) const;

 private:
  std::vector<Box3> triangle_boxes(const std::vector<int>& triangles) const;
  // Classifies surface_'s triangles and (re)builds both trees: build's work after surface_ is set.
  void index_surface(const TetMesh& mesh, const std::vector<std::uint8_t>& operation_tets,
                     const std::vector<Vec3>& displacement);
  // Deformed positions from the rest mesh and displacement_of(v); returns the nodes that moved
  // among those it had positions for.
  template <typename DisplacementOf>
  std::vector<int> place_nodes(const TetMesh& mesh, DisplacementOf displacement_of);
  // A step's refit: place_nodes, the operation tree refitted, the other one where it moved.
  template <typename DisplacementOf>
  void refit_placed(const TetMesh& mesh, DisplacementOf displacement_of);
  // The other tree after `moved_nodes` moved (positions were known for nodes < known): its
  // triangles on them.
  void refit_other_tree(const std::vector<int>& moved_nodes, size_t known);
  BoundarySurface surface_;
  std::vector<std::uint8_t> operation_;
  std::vector<Vec3> positions_;
  // Per tree, its triangles (indices into surface_.triangles) in the tree's primitive order.
  std::vector<int> operation_triangles_, other_triangles_;
  std::vector<Tri> other_nodes_;  // the other triangles' nodes at the last rebuild of their tree
  // Per node, the other tree's primitives on it (CSR: other_of_node_[other_start_[v] ..
  // other_start_[v + 1]]), so a refit finds the few that moved from the nodes that did.
  std::vector<int> other_start_, other_of_node_;
  AabbTree operation_tree_, other_tree_;
};

// Does segment [p, q] cross triangle (a, b, c)? On a hit, s = the segment parameter.
bool segment_crosses_triangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                              const Vec3& c, double& s);

}  // namespace stc
