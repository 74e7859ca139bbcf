// Blade-tissue contact (docs/DESIGN.md section 7), the simplest honest model: the cutting edge is
// a segment, the tissue surface a triangle mesh at its deformed positions.
//
// A surface node of the operation part is TOUCHED when
//   (a) it is a vertex of a surface triangle the edge segment crosses (the blade has gone
//       through that triangle; a crossing within touch_distance of a vertex does not count:
//       that is the blade running through a node it already holds), or
//   (b) it lies within `touch_distance` of the segment (nodes already held on the blade
//       stay held; a tolerance, not exact zero, because the solver puts them there only to
//       its precision).
// Each touched node is held on the blade: imposed displacement = (closest point of the edge
// segment to the node's deformed position) - (rest position). Nodes of triangles merely
// near the blade are not pulled in, so contact does not creep along the surface. The
// simulation imposes these as Dirichlet values, solves, and reads the reaction force on the
// blade from the constrained rows (f = K u - f_ext there); when its magnitude exceeds
// scalpel.cut_pressure, it cuts (cutting/cut_sweep.hpp).
#pragma once

#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/collision/surface_bvh.hpp"

#include <vector>

namespace stc {

struct ContactNode {
  int node = -1;
  Vec3 imposed_displacement = Vec3::Zero();  // closest blade point - rest position
  double depth = 0;                          // how far the node is moved now (m)
};

struct BladeContact {
  std::vector<ContactNode> nodes;  // ascending by node
  std::vector<int>
      crossed_triangles;  // surface triangles the edge crosses (indices into bvh.surface())
};

BladeContact blade_contact(const SurfaceBvh& bvh, const TetMesh& mesh, const BladeEdge& edge,
                           double touch_distance);

}  // namespace stc
