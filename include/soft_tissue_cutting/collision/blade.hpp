// The scalpel's cutting edge as a segment (docs/SCENE.md "Scene file", `scalpel`): the pose origin
// is the tip, the edge runs from the tip along the pose's local +x for blade_length, the blade lies
// in its local x-z plane, so its normal is the local y axis.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

namespace stc {

struct BladeEdge {
  Vec3 tip = Vec3::Zero();      // pose origin
  Vec3 heel = Vec3::Zero();     // tip + blade_length * local x
  Vec3 normal = Vec3::UnitY();  // local y, unit
};

BladeEdge blade_edge(const BladePose& pose, double blade_length);

// Closest point of segment [a, b] to p.
Vec3 closest_point_on_segment(const Vec3& a, const Vec3& b, const Vec3& p);

// Closest point of triangle (a, b, c) to p; w: its barycentric weights.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3& w);

}  // namespace stc
