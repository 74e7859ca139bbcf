// (a) The node publishes the thigh surface: a closed triangle list (every edge used twice,
// in opposite directions), as many triangles as the core's boundary surface of
// make_thigh_scene(), per-vertex colours, latched; plus the markers' namespaces.
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "test_helpers.hpp"

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include <set>

using tissue_test::spin_until;

TEST(Surface, ClosedThighSurfaceWithCoreTriangleCount) {
  ros::NodeHandle nh;
  visualization_msgs::Marker::ConstPtr m = ros::topic::waitForMessage<visualization_msgs::Marker>(
      "/tissue/surface", nh, ros::Duration(20.0));
  ASSERT_TRUE(m) << "no message on /tissue/surface";
  EXPECT_EQ(m->type, visualization_msgs::Marker::TRIANGLE_LIST);
  EXPECT_EQ(m->header.frame_id, "tissue");
  EXPECT_EQ(m->ns, "tissue");
  ASSERT_EQ(m->points.size() % 3, 0u);
  EXPECT_EQ(m->colors.size(), m->points.size()) << "per-vertex colours";

  const stc::Scene scene = stc::make_thigh_scene();
  const stc::BoundarySurface core = stc::extract_boundary_surface(scene.mesh);
  const tissue_test::TriangleSoup soup = tissue_test::analyse(*m);
  EXPECT_EQ(soup.triangles, static_cast<int>(core.triangles.size()));
  EXPECT_EQ(soup.vertices, static_cast<int>(stc::boundary_nodes(core).size()));
  EXPECT_EQ(soup.bad_edges, 0) << "the surface must be closed and consistently oriented";
  for (const auto& c : m->colors) {
    EXPECT_GE(c.a, 0.99f);
    EXPECT_LE(c.r, 1.0f);
  }
}

TEST(Surface, Latched) {
  ros::NodeHandle nh;
  std::string latching;
  int received = 0;
  ros::Subscriber sub = nh.subscribe<visualization_msgs::Marker>(
      "/tissue/surface", 1,
      boost::function<void(const ros::MessageEvent<visualization_msgs::Marker const>&)>(
          [&](const ros::MessageEvent<visualization_msgs::Marker const>& e) {
            ++received;
            latching = (*e.getConnectionHeaderPtr())["latching"];
          }));
  ASSERT_TRUE(spin_until([&] { return received > 0; }, 10.0));
  EXPECT_EQ(latching, "1");
}

TEST(Surface, MarkerNamespaces) {
  ros::NodeHandle nh;
  visualization_msgs::MarkerArray::ConstPtr a =
      ros::topic::waitForMessage<visualization_msgs::MarkerArray>("/tissue/markers", nh,
                                                                  ros::Duration(10.0));
  ASSERT_TRUE(a);
  std::set<std::string> ns;
  for (const auto& m : a->markers) {
    ns.insert(m.ns);
    EXPECT_EQ(m.header.frame_id, "tissue");
  }
  for (const char* want : {"tissue", "cut_faces", "scalpel", "operation_region"})
    EXPECT_TRUE(ns.count(want)) << "namespace " << want;
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_surface");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
