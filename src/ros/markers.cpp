#include "soft_tissue_cutting/ros/markers.hpp"

#include "soft_tissue_cutting/ros/conversions.hpp"

#include <algorithm>
#include <cmath>

namespace stc {
namespace ros_io {
namespace {

// Fixed light, roughly from where config/tissue.rviz's camera looks at the thigh's operation
// region (+x side, a little above), so the lit side faces the viewer. scripts/picture_view.py
// (MARKER_LIGHT) places a scene's picture camera on the lit side: keep the two the same.
const Vec3 kLight = Vec3(1.0, 0.35, 0.6).normalized();
constexpr double kAmbient = 0.35;

std_msgs::ColorRGBA rgba(double r, double g, double b, double a = 1.0) {
  std_msgs::ColorRGBA c;
  c.r = static_cast<float>(r);
  c.g = static_cast<float>(g);
  c.b = static_cast<float>(b);
  c.a = static_cast<float>(a);
  return c;
}

geometry_msgs::Point point(const Vec3& x) {
  geometry_msgs::Point p;
  p.x = x.x();
  p.y = x.y();
  p.z = x.z();
  return p;
}

// Displacement colormap: tissue pink at rest, through orange to pale yellow at s = 1.
Vec3 skin_colour(double s) {
  s = std::clamp(s, 0.0, 1.0);
  const Vec3 c0(0.93, 0.62, 0.58), c1(0.95, 0.45, 0.20), c2(1.00, 0.92, 0.45);
  return s < 0.5 ? c0 + (c1 - c0) * (2 * s) : c1 + (c2 - c1) * (2 * s - 1);
}
const Vec3 kCutColour(0.50, 0.06, 0.08);  // tissue interior: dark red

bool wanted(const BoundaryTriangle& t, SurfacePart part) {
  return part == SurfacePart::kAll || (part == SurfacePart::kCut) == t.cut;
}

}  // namespace

visualization_msgs::Marker surface_marker(const DeformedSurface& s, SurfacePart part,
                                          double max_displacement) {
  visualization_msgs::Marker m;
  m.ns = part == SurfacePart::kCut ? "cut_faces" : "tissue";
  m.id = 0;
  m.type = visualization_msgs::Marker::TRIANGLE_LIST;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1;
  m.scale.x = m.scale.y = m.scale.z = 1;
  m.color = rgba(1, 1, 1);

  // Per-vertex normals, averaged (area-weighted) over adjacent triangles of the same kind.
  const size_t n = s.positions.size();
  std::vector<Vec3> normal_skin(n, Vec3::Zero()), normal_cut(n, Vec3::Zero());
  size_t count = 0;
  for (const BoundaryTriangle& t : s.triangles) {
    if (!wanted(t, part)) continue;
    ++count;
    const Vec3& a = s.positions[t.nodes[0]];
    const Vec3 fn = (s.positions[t.nodes[1]] - a).cross(s.positions[t.nodes[2]] - a);
    auto& normals = t.cut ? normal_cut : normal_skin;
    for (int v : t.nodes) normals[v] += fn;
  }
  if (count == 0) {
    m.action = visualization_msgs::Marker::DELETE;
    return m;
  }
  m.points.reserve(3 * count);
  m.colors.reserve(3 * count);
  const double scale = max_displacement > 0 ? 1.0 / max_displacement : 0.0;
  for (const BoundaryTriangle& t : s.triangles) {
    if (!wanted(t, part)) continue;
    for (int v : t.nodes) {
      const Vec3 nrm = (t.cut ? normal_cut : normal_skin)[v].normalized();
      const Vec3 base = t.cut ? kCutColour
                              : skin_colour(v < static_cast<int>(s.displacement.size())
                                                ? s.displacement[v] * scale
                                                : 0.0);
      const double light = kAmbient + (1 - kAmbient) * std::max(0.0, nrm.dot(kLight));
      const Vec3 c = (base * light).cwiseMin(1.0);
      m.points.push_back(point(s.positions[v]));
      m.colors.push_back(rgba(c.x(), c.y(), c.z()));
    }
  }
  return m;
}

visualization_msgs::MarkerArray scalpel_markers(const std::optional<BladePose>& blade,
                                                double blade_length, bool cutting) {
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker b;
  b.ns = "scalpel";
  b.id = 0;
  b.type = visualization_msgs::Marker::TRIANGLE_LIST;
  b.scale.x = b.scale.y = b.scale.z = 1;
  b.pose.orientation.w = 1;
  visualization_msgs::Marker h = b;
  h.id = 1;
  h.type = visualization_msgs::Marker::CUBE;
  if (!blade) {
    b.action = h.action = visualization_msgs::Marker::DELETE;
    array.markers = {b, h};
    return array;
  }
  const double len = blade_length > 0 ? blade_length : 0.02;
  const double height = 0.3 * len;
  // Blade in the local x-z plane: tip at the origin, edge along +x; both windings so it is
  // visible from either side.
  b.action = visualization_msgs::Marker::ADD;
  b.pose = to_pose_msg(*blade);
  b.color = cutting ? rgba(0.95, 0.25, 0.2) : rgba(0.78, 0.80, 0.85);
  const Vec3 tip(0, 0, 0), heel(len, 0, 0), back(len, 0, height);
  for (const Vec3& p : {tip, heel, back, tip, back, heel}) b.points.push_back(point(p));
  // Handle: a box continuing the blade beyond its heel.
  const double handle = 0.04;
  h.action = visualization_msgs::Marker::ADD;
  BladePose hp = *blade;
  hp.position = blade->position + blade->orientation * Vec3(len + 0.5 * handle, 0, 0.5 * height);
  h.pose = to_pose_msg(hp);
  h.scale.x = handle;
  h.scale.y = 0.0025;
  h.scale.z = 0.005;
  h.color = rgba(0.45, 0.55, 0.75);
  array.markers = {b, h};
  return array;
}

visualization_msgs::Marker contact_marker(const std::vector<Vec3>& held_points) {
  visualization_msgs::Marker m;
  m.ns = "contact";
  m.id = 0;
  m.type = visualization_msgs::Marker::SPHERE_LIST;
  m.pose.orientation.w = 1;
  m.scale.x = m.scale.y = m.scale.z = 0.0015;
  m.color = rgba(0.2, 0.85, 0.35);
  m.action =
      held_points.empty() ? visualization_msgs::Marker::DELETE : visualization_msgs::Marker::ADD;
  for (const Vec3& p : held_points) m.points.push_back(point(p));
  return m;
}

visualization_msgs::MarkerArray operation_region_markers(const OperationRegion& region) {
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker m;
  m.ns = "operation_region";
  m.id = 0;
  m.type = visualization_msgs::Marker::LINE_LIST;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1;
  m.scale.x = 0.0006;  // line width, m
  m.color = rgba(0.3, 0.7, 1.0, 0.8);
  // `follow`: the ball where it is now (it moves with the blade).
  if (region.kind == OperationRegion::Kind::kSphere ||
      region.kind == OperationRegion::Kind::kFollow) {
    const Vec3 c = region.sphere.center;
    const double r = region.sphere.radius;
    const int segments = 64;
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < segments; ++i)
        for (int k : {i, i + 1}) {
          const double a = 2 * M_PI * k / segments;
          Vec3 p = c;
          p[u] += r * std::cos(a);
          p[v] += r * std::sin(a);
          m.points.push_back(point(p));
        }
    }
  } else if (region.kind == OperationRegion::Kind::kBox) {
    const Vec3 lo = region.box.min, hi = region.box.max;
    auto corner = [&](int i) {
      return Vec3(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
    };
    for (int i = 0; i < 8; ++i)
      for (int bit : {1, 2, 4})
        if (!(i & bit)) {
          m.points.push_back(point(corner(i)));
          m.points.push_back(point(corner(i | bit)));
        }
  } else {
    return array;  // all / none: nothing to outline
  }
  array.markers.push_back(m);
  return array;
}

}  // namespace ros_io
}  // namespace stc
