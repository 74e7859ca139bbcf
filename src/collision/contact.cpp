#include "soft_tissue_cutting/collision/contact.hpp"

#include <algorithm>
#include <map>

namespace stc {

BladeContact blade_contact(const SurfaceBvh& bvh, const TetMesh& mesh, const BladeEdge& edge,
                           double touch_distance) {
  BladeContact contact;
  std::map<int, Vec3> touched;  // node -> closest blade point
  auto touch = [&](int v) {
    if (!touched.count(v))
      touched[v] = closest_point_on_segment(edge.tip, edge.heel, bvh.position(v));
  };
  for (int t : bvh.near_segment(edge.tip, edge.heel, touch_distance)) {
    if (!bvh.is_operation(t)) continue;
    const Tri& n = bvh.surface().triangles[t].nodes;
    double s;
    bool crossed = segment_crosses_triangle(edge.tip, edge.heel, bvh.position(n[0]),
                                            bvh.position(n[1]), bvh.position(n[2]), s);
    if (crossed) {
      // Passing through (or right by) a vertex is not going through the triangle: that is a
      // node already held on the blade, and counting it would pull its whole fan in.
      const Vec3 x = edge.tip + s * (edge.heel - edge.tip);
      for (int v : n) crossed &= (x - bvh.position(v)).norm() > touch_distance;
    }
    if (crossed) {
      contact.crossed_triangles.push_back(t);
      for (int v : n) touch(v);
      continue;
    }
    for (int v : n)
      if ((closest_point_on_segment(edge.tip, edge.heel, bvh.position(v)) - bvh.position(v))
              .norm() <= touch_distance)
        touch(v);
  }
  std::sort(contact.crossed_triangles.begin(), contact.crossed_triangles.end());
  for (const auto& [v, on_blade] : touched)
    contact.nodes.push_back({v, on_blade - mesh.nodes[v], (on_blade - bvh.position(v)).norm()});
  return contact;
}

}  // namespace stc
