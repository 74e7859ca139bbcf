// Marker building without a master: sizes, namespaces, colours and DELETE actions.
#include "soft_tissue_cutting/ros/markers.hpp"

#include <gtest/gtest.h>

namespace stc::ros_io {
namespace {

// A tetrahedron's surface: three skin faces and one cut face; node 3 displaced 5 mm.
DeformedSurface tet_surface() {
  DeformedSurface s;
  s.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  s.displacement = {0, 0, 0, 0.005};
  auto tri = [](int a, int b, int c, bool cut) {
    BoundaryTriangle t;
    t.nodes = {a, b, c};
    t.cut = cut;
    return t;
  };
  s.triangles = {tri(0, 2, 1, false), tri(0, 1, 3, false), tri(0, 3, 2, false), tri(1, 2, 3, true)};
  return s;
}

TEST(Markers, SurfaceSizesAndNamespaces) {
  const DeformedSurface s = tet_surface();
  const auto all = surface_marker(s, SurfacePart::kAll);
  EXPECT_EQ(all.ns, "tissue");
  EXPECT_EQ(all.type, visualization_msgs::Marker::TRIANGLE_LIST);
  EXPECT_EQ(all.action, visualization_msgs::Marker::ADD);
  EXPECT_EQ(all.points.size(), 12u);
  EXPECT_EQ(all.colors.size(), 12u);
  EXPECT_TRUE(all.text.empty());  // no state in strings
  const auto skin = surface_marker(s, SurfacePart::kSkin);
  EXPECT_EQ(skin.points.size(), 9u);
  const auto cut = surface_marker(s, SurfacePart::kCut);
  EXPECT_EQ(cut.ns, "cut_faces");
  EXPECT_EQ(cut.points.size(), 3u);
  EXPECT_EQ(all.points[0].x, 0.0);
  EXPECT_EQ(all.points[1].y, 1.0);  // triangle (0, 2, 1): second vertex is node 2
}

TEST(Markers, ColoursShowCutFacesAndDisplacement) {
  const auto cut = surface_marker(tet_surface(), SurfacePart::kCut);
  for (const auto& c : cut.colors) {  // dark red, lit
    EXPECT_GT(c.r, 2.5 * c.g);
    EXPECT_LE(c.r, 0.5f + 1e-6f);
    EXPECT_EQ(c.a, 1.0f);
  }
  // Skin: node 3 (5 mm = max_displacement) is pale yellow, rest pink; compare the hue by g/r.
  const auto skin = surface_marker(tet_surface(), SurfacePart::kSkin, 0.005);
  double g_over_r_rest = 0, g_over_r_moved = 0;
  for (size_t i = 0; i < skin.points.size(); ++i) {
    const double ratio = skin.colors[i].g / skin.colors[i].r;
    (skin.points[i].z == 1.0 ? g_over_r_moved : g_over_r_rest) = ratio;
  }
  EXPECT_NEAR(g_over_r_rest, 0.62 / 0.93, 1e-3);
  EXPECT_NEAR(g_over_r_moved, 0.92 / 1.00, 1e-3);
}

TEST(Markers, EmptyPartIsADelete) {
  DeformedSurface s = tet_surface();
  s.triangles.pop_back();  // no cut face
  EXPECT_EQ(surface_marker(s, SurfacePart::kCut).action, visualization_msgs::Marker::DELETE);
}

TEST(Markers, ScalpelBladeAndHandle) {
  EXPECT_EQ(scalpel_markers(std::nullopt, 0.02, false).markers.size(), 2u);
  for (const auto& m : scalpel_markers(std::nullopt, 0.02, false).markers)
    EXPECT_EQ(m.action, visualization_msgs::Marker::DELETE);
  BladePose p;
  p.position = Vec3(0.1, 0.2, 0.3);
  const auto a = scalpel_markers(p, 0.02, true);
  ASSERT_EQ(a.markers.size(), 2u);
  const auto& blade = a.markers[0];
  EXPECT_EQ(blade.ns, "scalpel");
  EXPECT_EQ(blade.points.size(), 6u);  // one triangle, both windings
  EXPECT_EQ(blade.points[1].x, 0.02);  // heel at blade_length along local x
  EXPECT_EQ(blade.pose.position.x, 0.1);
  EXPECT_GT(blade.color.r, 0.9f);  // cutting: red
  EXPECT_LT(scalpel_markers(p, 0.02, false).markers[0].color.r, 0.8f);
  const auto& handle = a.markers[1];
  EXPECT_EQ(handle.type, visualization_msgs::Marker::CUBE);
  EXPECT_EQ(handle.scale.x, 0.04);
  EXPECT_NEAR(handle.pose.position.x, 0.1 + 0.02 + 0.02, 1e-15);
}

TEST(Markers, OperationRegionOutline) {
  OperationRegion sphere;
  sphere.kind = OperationRegion::Kind::kSphere;
  sphere.sphere = Sphere{Vec3(1, 2, 3), 0.5};
  const auto s = operation_region_markers(sphere);
  ASSERT_EQ(s.markers.size(), 1u);
  EXPECT_EQ(s.markers[0].ns, "operation_region");
  EXPECT_EQ(s.markers[0].points.size(), 3u * 64u * 2u);
  for (const auto& p : s.markers[0].points)
    EXPECT_NEAR((Vec3(p.x, p.y, p.z) - Vec3(1, 2, 3)).norm(), 0.5, 1e-12);
  OperationRegion box;
  box.kind = OperationRegion::Kind::kBox;
  box.box = Box{Vec3(0, 0, 0), Vec3(1, 1, 1)};
  EXPECT_EQ(operation_region_markers(box).markers[0].points.size(), 24u);  // 12 edges
  OperationRegion all;
  all.kind = OperationRegion::Kind::kAll;
  EXPECT_TRUE(operation_region_markers(all).markers.empty());
}

}  // namespace
}  // namespace stc::ros_io
