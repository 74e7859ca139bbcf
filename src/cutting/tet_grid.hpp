// A uniform grid over the rest-position bounding boxes of tets, so a sweep finds the tets it
// may meet without scanning the mesh.
//
// Why the grid only ever grows: a bisected tet's children lie inside the parent's box. A child
// that keeps its parent's index is therefore still listed in (a superset of) its cells, and
// appended tets are inserted; a tet whose box may have grown (a node moved, a flip) is inserted
// again. Queries filter by the exact box, which the grid keeps per tet (a tet's four corners
// are five scattered reads; its kept box one): whoever changes a tet's nodes tells the grid,
// by insert() or, for a box that can only have shrunk, refresh().
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <vector>

namespace stc {

// Rest-position bounding box of a tet.
void tet_bounds(const TetMesh& mesh, int tet, Vec3& lo, Vec3& hi);

class TetGrid {
 public:
  // Grid over the tets with include[t] != 0 (all tets when include is empty).
  void build(const TetMesh& mesh, const std::vector<std::uint8_t>& include);
  void insert(const TetMesh& mesh, int tet);
  // Keeps `tet`'s box up to date after its nodes changed within its old box (a bisected tet's
  // kept child): it stays listed where it was.
  void refresh(const TetMesh& mesh, int tet);
  // Listed tets whose box overlaps [lo, hi], ascending and unique.
  std::vector<int> query(const TetMesh& mesh, const Vec3& lo, const Vec3& hi) const;
  // Whether query() would list any tet: stops at the first (no list, no sort). The moving
  // region asks this for every sample of a sweep at every cutting step.
  bool any(const TetMesh& mesh, const Vec3& lo, const Vec3& hi) const;
  // The union of the boxes of the listed tets that overlap [lo, hi], grown from [ulo, uhi]
  // (no list, no sort: a tet listed in several cells is merged again, which changes nothing).
  void grow_by_overlapping(const TetMesh& mesh, const Vec3& lo, const Vec3& hi, Vec3& ulo,
                           Vec3& uhi) const;

 private:
  std::array<int, 3> cell_of(const Vec3& p) const;
  // Calls stop(t, box_lo, box_hi) for every listed tet (once per cell it is listed in) whose
  // box overlaps [lo, hi], until it returns true; returns whether it did.
  template <class Stop>
  bool first_overlapping(const Vec3& lo, const Vec3& hi, Stop stop) const {
    const auto a = cell_of(lo), b = cell_of(hi);
    for (int k = a[2]; k <= b[2]; ++k)
      for (int j = a[1]; j <= b[1]; ++j)
        for (int i = a[0]; i <= b[0]; ++i)
          for (int t : cells_[(static_cast<size_t>(k) * dims_[1] + j) * dims_[0] + i]) {
            const Box& box = boxes_[static_cast<size_t>(t)];
            if ((box.lo.array() <= hi.array()).all() && (box.hi.array() >= lo.array()).all() &&
                stop(t, box.lo, box.hi))
              return true;
          }
    return false;
  }
  struct Box {
    Vec3 lo, hi;
  };
  Vec3 origin_ = Vec3::Zero();
  double cell_size_ = 1.0;
  std::array<int, 3> dims_ = {1, 1, 1};
  std::vector<std::vector<int>> cells_;
  std::vector<Box> boxes_;              // per tet: its rest box when last inserted or refreshed
  mutable std::vector<unsigned> seen_;  // per tet: query stamp, to report each tet once
  mutable unsigned stamp_ = 0;
};

}  // namespace stc
