#include "soft_tissue_cutting/collision/blade.hpp"

#include <algorithm>

namespace stc {

BladeEdge blade_edge(const BladePose& pose, double blade_length) {
  const Eigen::Matrix3d r = pose.orientation.normalized().toRotationMatrix();
  BladeEdge edge;
  edge.tip = pose.position;
  edge.heel = pose.position + blade_length * r.col(0);
  edge.normal = r.col(1);
  return edge;
}

Vec3 closest_point_on_segment(const Vec3& a, const Vec3& b, const Vec3& p) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 <= 0) return a;
  const double s = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return a + s * ab;
}

}  // namespace stc
