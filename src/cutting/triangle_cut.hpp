// Inserting planar cut triangles into the tet mesh (steps a-c of the cut), in two phases:
//   1. split_along_triangle: classify nodes against the triangle's plane (snapping the near
//      ones to "on"), bisect the edges that cross the triangle;
//   2. mark_faces_on_triangle: mark the faces that now lie on it.
// All triangles of a cut are split before any is marked, because splits for one triangle
// create faces on a neighbouring one (near their shared edge) that its own split phase never
// saw. Separation (separation.hpp) comes after.
#pragma once

#include "cutting/cut_state.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"

#include <array>
#include <set>
#include <unordered_map>

namespace stc {

using FaceKey = std::array<int, 3>;  // sorted node triple

// A cut triangle and the sides its split phase gave the nodes (-1, +1, or 0 = on the cut).
// Nodes not yet classified are classified on demand with the same snap rule.
class TriangleClassification {
 public:
  TriangleClassification(const Vec3& a, const Vec3& b, const Vec3& c, double snap_tolerance);
  bool degenerate() const { return degenerate_; }
  // Is the projection of p onto the plane inside the triangle, with barycentric slack tol?
  bool contains(const Vec3& p, double tol) const;
  double distance(const TetMesh& mesh, int v) const { return normal_.dot(mesh.nodes[v] - a_); }
  int side(const TetMesh& mesh, const CutState& state, int v);
  void set_on(int v) { side_[v] = 0; }
  const Vec3& normal() const { return normal_; }
  void bounds(Vec3& lo, Vec3& hi) const;

 private:
  Vec3 a_, b_, c_, normal_;
  double double_area_ = 0, snap_tolerance_ = 0;
  bool degenerate_ = false;
  std::unordered_map<int, int> side_;
};

// Phase 1. Splits only edges that are not interface edges (both ends locked) and whose
// crossing point is inside the triangle; new nodes, split counts and changed tets go to
// `result`.
void split_along_triangle(TetMesh& mesh, CutState& state, TriangleClassification& triangle,
                          const CutOptions& options, CutResult& result);

// Phase 2. Marks interior faces between two cuttable tets with three "on" nodes, the tets'
// fourth nodes on opposite sides and the centroid inside the triangle, among the tets that
// overlap [lo, hi]. Newly marked faces are added to `new_faces`.
void mark_faces_on_triangle(TetMesh& mesh, const CutState& state, TriangleClassification& triangle,
                            const Vec3& lo, const Vec3& hi, const CutOptions& options,
                            CutResult& result, std::set<FaceKey>& new_faces);

// The tet across local face `face` of `tet` and that tet's local index of the face, or
// {-1, -1} on the boundary.
std::pair<int, int> neighbour_across(const TetMesh& mesh, const CutState& state, int tet, int face);

}  // namespace stc
