#include "soft_tissue_cutting/collision/tip_contact.hpp"

#include "soft_tissue_cutting/collision/blade.hpp"

#include <limits>

namespace stc {

std::optional<ContactAnchor> find_contact(const TetMesh& mesh, const Eigen::VectorXd& u,
                                          const std::vector<BoundaryTriangle>& triangles,
                                          const Vec3& tip, double reach) {
  std::optional<ContactAnchor> best;
  double best_distance = std::numeric_limits<double>::max();
  for (const BoundaryTriangle& t : triangles) {
    if (t.cut) continue;  // the blade presses the skin, not the walls of its own incision
    Vec3 x[3];
    for (int k = 0; k < 3; ++k) x[k] = mesh.nodes[t.nodes[k]] + u.segment<3>(3 * t.nodes[k]);
    const Vec3 n = (x[1] - x[0]).cross(x[2] - x[0]);
    if (n.squaredNorm() == 0) continue;
    Vec3 w;
    const Vec3 q = closest_point_on_triangle(tip, x[0], x[1], x[2], w);
    const double distance = (tip - q).norm();
    // Beneath the triangle itself: the tip projects inside it (so the push is along its
    // normal, not sideways onto a neighbour's edge) and lies on its inner side.
    constexpr double kEdgeSlack = 1e-9;
    const Vec3 nn = n.normalized();
    if (distance > reach || distance >= best_distance || (tip - q).dot(nn) > 0) continue;
    if ((tip - q).cross(nn).norm() > kEdgeSlack * (1 + distance / reach) + 1e-12 &&
        w.minCoeff() <= 0)
      continue;
    best_distance = distance;
    best = ContactAnchor{t.nodes,
                         {x[0] - mesh.nodes[t.nodes[0]], x[1] - mesh.nodes[t.nodes[1]],
                          x[2] - mesh.nodes[t.nodes[2]]},
                         q,
                         n.normalized()};
  }
  return best;
}

std::optional<std::array<Vec3, 3>> anchored_displacements(const ContactAnchor& anchor,
                                                          const Vec3& tip) {
  const Vec3 push = tip - anchor.touch_point;
  if (push.dot(anchor.touch_normal) >= 0) return std::nullopt;
  std::array<Vec3, 3> u = anchor.touch_displacement;
  for (Vec3& ui : u) ui += push;
  return u;
}

}  // namespace stc
