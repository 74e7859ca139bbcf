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

// Ericson, Real-Time Collision Detection, 5.1.5.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                               Vec3& w) {
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

}  // namespace stc
