#include "soft_tissue_cutting/collision/tip_contact.hpp"

#include <limits>

namespace stc {
namespace {

// Closest point of triangle (a, b, c) to p, with its barycentric weights (Ericson,
// Real-Time Collision Detection, 5.1.5).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3& w) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return w = Vec3(1, 0, 0), a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return w = Vec3(0, 1, 0), b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return w = Vec3(1 - v, v, 0), a + v * ab;
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return w = Vec3(0, 0, 1), c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double v = d2 / (d2 - d6);
    return w = Vec3(1 - v, 0, v), a + v * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return w = Vec3(0, 1 - v, v), b + v * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, x = vc * denom;
  return w = Vec3(1 - v - x, v, x), a + ab * v + ac * x;
}

}  // namespace

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
    const Vec3 q = closest_on_triangle(tip, x[0], x[1], x[2], w);
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
