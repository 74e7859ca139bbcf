// (f) A robot drives the scalpel through tf (~scalpel_frame, docs/ROS.md): the tissue and the
// robot's base are placed in `world` by static transforms (turned and shifted), and the tool tip
// moves under the base by a dynamic transform. The poses of test/bags/thigh_cut.bag, given in
// the tissue frame, are turned into tool-tip transforms under the base and broadcast one by one;
// the same poses go on /scalpel/pose to a second node. Each is held until both nodes' ~stats
// carry its stamp (scalpel_stamp: for the tf node the transform's stamp). Then: the tf-driven
// blade pressed (in_contact, a wrench) and cut (cuts, tets split), the `scalpel` marker sits
// where the pose put it in the tissue frame (to 1e-9 m), and the two nodes end in the same cut
// (cut steps, tets split, tets, nodes): driving through tf is driving through the topic.
#include "test_helpers.hpp"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/SimStats.h>
#include <std_msgs/String.h>
#include <tf2/LinearMath/Transform.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

using tissue_test::spin_for;
using tissue_test::spin_until;

namespace {

struct Node {
  std::vector<soft_tissue_cutting::SimStats> stats;
  std::string hash;
  bool pressed = false;
  double max_force = 0;
};

geometry_msgs::TransformStamped placed(const std::string& parent, const std::string& child,
                                       const tf2::Transform& t) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = ros::Time::now();
  m.header.frame_id = parent;
  m.child_frame_id = child;
  m.transform = tf2::toMsg(t);
  return m;
}

TEST(TfScalpel, ARobotsToolFrameCutsLikeTheTopic) {
  ros::NodeHandle nh;
  std::string path;
  ASSERT_TRUE(ros::param::get("~bag", path));
  const std::vector<geometry_msgs::PoseStamped> poses = tissue_test::read_scalpel_poses(path);
  ASSERT_GT(poses.size(), 50u);

  Node tf_node, topic_node;
  std::optional<geometry_msgs::Pose> marker;  // the tf node's `scalpel` marker
  auto stats_cb = [](Node* n) {
    return [n](const soft_tissue_cutting::SimStats::ConstPtr& s) {
      n->stats.push_back(*s);
      n->pressed |= s->in_contact;
      n->max_force = std::max(n->max_force, s->contact_force);
    };
  };
  auto hash_cb = [](Node* n) {
    return [n](const std_msgs::String::ConstPtr& h) { n->hash = h->data; };
  };
  ros::Subscriber s1 =
      nh.subscribe<soft_tissue_cutting::SimStats>("/tissue/stats", 1000, stats_cb(&tf_node));
  ros::Subscriber s2 = nh.subscribe<soft_tissue_cutting::SimStats>("/tissue_topic/stats", 1000,
                                                                   stats_cb(&topic_node));
  ros::Subscriber h1 = nh.subscribe<std_msgs::String>("/tissue/mesh_hash", 10, hash_cb(&tf_node));
  ros::Subscriber h2 =
      nh.subscribe<std_msgs::String>("/tissue_topic/mesh_hash", 10, hash_cb(&topic_node));
  ros::Subscriber m1 = nh.subscribe<visualization_msgs::MarkerArray>(
      "/tissue/markers", 100, [&marker](const visualization_msgs::MarkerArray::ConstPtr& a) {
        for (const auto& m : a->markers)
          if (m.ns == "scalpel" && m.id == 0 && m.action == visualization_msgs::Marker::ADD)
            marker = m.pose;
      });
  ros::Publisher pose_pub = nh.advertise<geometry_msgs::PoseStamped>("/scalpel/pose", 100);
  ASSERT_TRUE(ros::service::waitForService("/tissue/reset", ros::Duration(20)));
  ASSERT_TRUE(ros::service::waitForService("/tissue_topic/reset", ros::Duration(20)));
  ASSERT_TRUE(spin_until([&] { return pose_pub.getNumSubscribers() > 0; }, 10.0));

  // world <- tissue and world <- robot_base (static), robot_base <- tool_tip (each pose).
  tf2::Quaternion q_tissue, q_base;
  q_tissue.setRPY(0.3, -0.2, 0.9);
  q_base.setRPY(0.0, 0.4, -1.7);
  const tf2::Transform world_tissue(q_tissue, tf2::Vector3(0.4, -0.1, 0.8));
  const tf2::Transform world_base(q_base, tf2::Vector3(-0.3, 0.5, 0.2));
  tf2_ros::StaticTransformBroadcaster statics;
  statics.sendTransform(std::vector<geometry_msgs::TransformStamped>{
      placed("world", "tissue", world_tissue), placed("world", "robot_base", world_base)});
  tf2_ros::TransformBroadcaster tool;
  spin_for(0.5);

  for (size_t i = 0; i < poses.size(); ++i) {
    tf2::Transform tissue_tool;
    tf2::fromMsg(poses[i].pose, tissue_tool);
    const tf2::Transform base_tool = world_base.inverse() * world_tissue * tissue_tool;
    const ros::Time stamp = ros::Time::now();
    geometry_msgs::PoseStamped p = poses[i];
    p.header.stamp = stamp;
    p.header.frame_id = "tissue";
    geometry_msgs::TransformStamped t = placed("robot_base", "tool_tip", base_tool);
    t.header.stamp = stamp;
    const size_t seen_tf = tf_node.stats.size(), seen_topic = topic_node.stats.size();
    tool.sendTransform(t);
    pose_pub.publish(p);
    ASSERT_TRUE(spin_until(
        [&] {
          return tissue_test::stepped_on(tf_node.stats, seen_tf, stamp) &&
                 tissue_test::stepped_on(topic_node.stats, seen_topic, stamp);
        },
        5.0))
        << "pose " << i << " was not stepped on by "
        << (tissue_test::stepped_on(tf_node.stats, seen_tf, stamp) ? "the topic node"
                                                                   : "the tf node");
  }
  spin_for(1.5);  // the last surface, marker and hash

  ASSERT_FALSE(tf_node.stats.empty());
  const auto& last = tf_node.stats.back();
  std::printf(
      "[tf_scalpel] %zu poses through tf: %u cuts, %u tets split, %u tets, peak force "
      "%.3f N, hash %s; through the topic: %u cuts, %u tets, hash %s\n",
      poses.size(), last.cuts, last.tets_split, last.tets, tf_node.max_force, tf_node.hash.c_str(),
      topic_node.stats.back().cuts, topic_node.stats.back().tets, topic_node.hash.c_str());
  EXPECT_TRUE(tf_node.pressed) << "the tf-driven blade never touched the tissue";
  EXPECT_GT(tf_node.max_force, 1e-3);
  EXPECT_GT(last.cuts, 0u) << "the tf-driven blade never cut";
  EXPECT_GT(last.tets_split, 0u);
  // The same cut: tf's composition of the transforms moves the poses by ~1e-16, so the rest
  // positions (and ~mesh_hash) may differ in their last digits, not the cut's topology.
  EXPECT_FALSE(tf_node.hash.empty());
  EXPECT_EQ(last.cuts, topic_node.stats.back().cuts) << "tf and topic drove the blade differently";
  EXPECT_EQ(last.tets_split, topic_node.stats.back().tets_split);
  EXPECT_EQ(last.tets, topic_node.stats.back().tets);
  EXPECT_EQ(last.nodes, topic_node.stats.back().nodes);

  // The marker shows the blade where the last pose put it in the tissue frame.
  ASSERT_TRUE(marker.has_value()) << "no scalpel marker";
  const geometry_msgs::Pose& want = poses.back().pose;
  EXPECT_NEAR(marker->position.x, want.position.x, 1e-9);
  EXPECT_NEAR(marker->position.y, want.position.y, 1e-9);
  EXPECT_NEAR(marker->position.z, want.position.z, 1e-9);
  const double dot =
      marker->orientation.x * want.orientation.x + marker->orientation.y * want.orientation.y +
      marker->orientation.z * want.orientation.z + marker->orientation.w * want.orientation.w;
  EXPECT_NEAR(std::abs(dot), 1.0, 1e-9) << "the blade is turned";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_tf_scalpel");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
