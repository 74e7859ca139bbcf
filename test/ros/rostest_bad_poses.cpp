// (c) Bad poses are dropped, the node keeps publishing ~stats at its rate. The blade drawn in
// ~markers (namespace scalpel, id 0) shows which pose the node is using.
#include "test_helpers.hpp"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/SimStats.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <limits>
#include <optional>

using tissue_test::spin_for;
using tissue_test::spin_until;

namespace {

struct Fixture : testing::Test {
  ros::NodeHandle nh;
  ros::Publisher pose_pub;
  ros::Subscriber markers_sub, stats_sub;
  std::optional<geometry_msgs::Point> blade;  // from the latest ~markers
  int stats_count = 0;
  double rate_hz = 0;

  void SetUp() override {
    pose_pub = nh.advertise<geometry_msgs::PoseStamped>("/scalpel/pose", 100);
    markers_sub = nh.subscribe<visualization_msgs::MarkerArray>(
        "/tissue/markers", 100, [this](const visualization_msgs::MarkerArray::ConstPtr& a) {
          for (const auto& m : a->markers)
            if (m.ns == "scalpel" && m.id == 0) {
              if (m.action == visualization_msgs::Marker::ADD)
                blade = m.pose.position;
              else
                blade.reset();
            }
        });
    stats_sub = nh.subscribe<soft_tissue_cutting::SimStats>(
        "/tissue/stats", 1000, [this](const soft_tissue_cutting::SimStats::ConstPtr& s) {
          ++stats_count;
          rate_hz = s->rate_hz;
        });
    ASSERT_TRUE(ros::service::waitForService("/tissue/reset", ros::Duration(20)));
    ASSERT_TRUE(spin_until([this] { return pose_pub.getNumSubscribers() > 0; }, 10.0));
    std_srvs::Trigger t;
    ASSERT_TRUE(ros::service::call("/tissue/reset", t));
    spin_for(0.2);
  }

  void send(double x, double y, double z, const std::string& frame = "tissue", double qw = 1.0) {
    geometry_msgs::PoseStamped p;
    p.header.frame_id = frame;
    p.header.stamp = ros::Time(1.0);  // ancient stamp: never a reason to drop
    p.pose.position.x = x;
    p.pose.position.y = y;
    p.pose.position.z = z;
    p.pose.orientation.w = qw;
    pose_pub.publish(p);
  }

  bool blade_at(double x, double y, double z, double timeout = 3.0) {
    return spin_until(
        [&] {
          return blade && std::abs(blade->x - x) < 1e-9 && std::abs(blade->y - y) < 1e-9 &&
                 std::abs(blade->z - z) < 1e-9;
        },
        timeout);
  }
};

// Outside the thigh (outer radius 0.06): no contact, no cut.
constexpr double kX = 0.10, kY = 0.003, kZ = 0.048;

}  // namespace

TEST_F(Fixture, FirstPoseMustBeNearTheTissue) {
  send(10.0, 0.0, 0.0);  // 10 m away: refused even as the first pose since ~reset
  send(1e300, 0.0, 0.0);
  spin_for(1.2);  // ~markers repeats at least once a second
  EXPECT_FALSE(blade) << "a first pose far from the tissue was accepted";
  send(kX, kY, kZ);  // 4 cm outside the thigh: within ~max_pose_jump of its box
  EXPECT_TRUE(blade_at(kX, kY, kZ));
}

TEST_F(Fixture, BadPosesDroppedAndRateKept) {
  send(kX, kY, kZ);
  ASSERT_TRUE(blade_at(kX, kY, kZ));

  // Baseline rate.
  stats_count = 0;
  spin_for(2.0);
  const int baseline = stats_count;

  // 2 s of bad poses at ~400 Hz: NaN, Inf, zero quaternion, unknown frame, absurd jump.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  stats_count = 0;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(2.0);
  int sent = 0;
  while (ros::WallTime::now() < end) {
    switch (sent++ % 5) {
      case 0:
        send(nan, kY, kZ);
        break;
      case 1:
        send(kX, inf, kZ);
        break;
      case 2:
        send(kX, kY, kZ, "tissue", 0.0);
        break;
      case 3:
        send(kX + 0.001, kY, kZ, "no_such_frame");
        break;
      case 4:
        send(kX + 1.0, kY, kZ);
        break;
    }
    ros::spinOnce();
    ros::WallDuration(0.0025).sleep();
  }
  const int during = stats_count;
  std::printf(
      "[bad_poses] ~stats: %d msgs in 2 s before, %d in 2 s under %d bad poses; "
      "node reports %.1f Hz\n",
      baseline, during, sent, rate_hz);
  EXPECT_GT(baseline, 100) << "~stats should come at ~100 Hz";
  EXPECT_GE(during, 0.8 * baseline) << "the node must keep its rate under bad input";

  spin_for(1.2);  // ~markers repeats at least once a second
  EXPECT_TRUE(blade_at(kX, kY, kZ, 0.1)) << "a bad pose was used";

  // A small, good move is accepted.
  send(kX + 0.01, kY, kZ);
  EXPECT_TRUE(blade_at(kX + 0.01, kY, kZ));
}

TEST_F(Fixture, PoseInOtherFrameIsTransformedAtLatestTime) {
  // world -> tissue: tissue sits 0.5 m above the world origin.
  tf2_ros::StaticTransformBroadcaster broadcaster;
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = ros::Time::now();
  tf.header.frame_id = "world";
  tf.child_frame_id = "tissue";
  tf.transform.translation.z = 0.5;
  tf.transform.rotation.w = 1;
  broadcaster.sendTransform(tf);
  spin_for(0.5);

  send(kX, kY, kZ);
  ASSERT_TRUE(blade_at(kX, kY, kZ));
  // Stamped long ago (ros::Time(1)) and in world: transformed with the latest transform.
  bool seen = false;
  for (int i = 0; i < 20 && !seen; ++i) {
    send(kX + 0.01, kY, kZ + 0.5, "world");
    seen = blade_at(kX + 0.01, kY, kZ, 0.25);
  }
  EXPECT_TRUE(seen) << "pose in frame world was not transformed into tissue";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_bad_poses");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
