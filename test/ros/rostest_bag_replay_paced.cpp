// (d, paced) A bag replayed the way `rosbag play` does it - at the recorded pace (and at 4x),
// not in lockstep - into a node with ~every_pose: the node steps on every pose, in order
// (each pose's stamp appears in ~stats' scalpel_stamp, none skipped, none out of order), and
// both replays end in the mesh (~mesh_hash) that the core cuts stepping once per pose
// (Simulation on make_thigh_scene(), no ROS): with ~every_pose a replay's cut does not depend
// on the pace or the machine's load. Without it the loop steps on the newest pose and a pose
// that arrives together with the next is skipped (docs/ROS.md, ~every_pose).
#include "test_helpers.hpp"

#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/ros/conversions.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/SimStats.h>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>

#include <string>
#include <vector>

using tissue_test::spin_for;
using tissue_test::spin_until;

namespace {

// The core's cut of the same poses, one step each, converted as the node converts them.
std::string core_hash(const std::vector<geometry_msgs::PoseStamped>& poses) {
  stc::Simulation sim(stc::make_thigh_scene());
  for (const auto& p : poses) sim.step(stc::ros_io::to_blade_pose(p.pose, 0.0));
  return sim.mesh_hash();
}

TEST(BagReplayPaced, EveryPoseIsSteppedOnAtAnyPace) {
  ros::NodeHandle nh;
  std::string path;
  ASSERT_TRUE(ros::param::get("~bag", path));
  const std::vector<geometry_msgs::PoseStamped> poses = tissue_test::read_scalpel_poses(path);
  ASSERT_GT(poses.size(), 50u);
  for (size_t i = 0; i < poses.size(); ++i)
    ASSERT_TRUE(!poses[i].header.stamp.isZero() && poses[i].header.frame_id == "tissue" &&
                (i == 0 || poses[i - 1].header.stamp < poses[i].header.stamp))
        << "the bag's poses need distinct increasing stamps in the tissue frame";
  const std::string expected = core_hash(poses);

  std::vector<soft_tissue_cutting::SimStats> stats;
  std::string hash;
  ros::Subscriber stats_sub = nh.subscribe<soft_tissue_cutting::SimStats>(
      "/tissue/stats", 10000,
      [&stats](const soft_tissue_cutting::SimStats::ConstPtr& s) { stats.push_back(*s); });
  ros::Subscriber hash_sub = nh.subscribe<std_msgs::String>(
      "/tissue/mesh_hash", 10, [&hash](const std_msgs::String::ConstPtr& h) { hash = h->data; });
  ros::Publisher pub = nh.advertise<geometry_msgs::PoseStamped>("/scalpel/pose", 1000);
  ASSERT_TRUE(ros::service::waitForService("/tissue/reset", ros::Duration(20)));
  ASSERT_TRUE(spin_until([&pub] { return pub.getNumSubscribers() > 0; }, 10.0));

  const double recorded = (poses.back().header.stamp - poses.front().header.stamp).toSec();
  for (double speed : {1.0, 4.0}) {
    std_srvs::Trigger t;
    ASSERT_TRUE(ros::service::call("/tissue/reset", t));
    spin_for(1.0);
    stats.clear();
    // Published on the wall clock at the recorded intervals / speed, like `rosbag play -r`.
    const ros::WallTime start = ros::WallTime::now();
    for (const auto& p : poses) {
      const double at = (p.header.stamp - poses.front().header.stamp).toSec() / speed;
      while ((ros::WallTime::now() - start).toSec() < at) {
        ros::spinOnce();
        ros::WallDuration(0.0005).sleep();
      }
      pub.publish(p);
    }
    const ros::Time last = poses.back().header.stamp;
    ASSERT_TRUE(
        spin_until([&] { return !stats.empty() && stats.back().scalpel_stamp == last; }, 20.0))
        << "the last pose was never stepped on (speed " << speed << ")";
    spin_for(1.5);  // the final hash
    // Every pose stepped on, in order.
    ros::Time previous;
    for (const auto& s : stats) {
      if (s.scalpel_stamp.isZero()) continue;
      EXPECT_GE(s.scalpel_stamp, previous) << "a pose was stepped on out of order";
      previous = s.scalpel_stamp;
    }
    size_t stepped = 0;
    for (const auto& p : poses) stepped += tissue_test::stepped_on(stats, 0, p.header.stamp);
    std::printf(
        "[bag_replay_paced] speed %.0fx: %zu poses over %.2f s, %zu steps, %zu poses "
        "stepped on; cuts %u, tets %u; hash %s (core %s)\n",
        speed, poses.size(), recorded / speed, stats.size(), stepped, stats.back().cuts,
        stats.back().tets, hash.c_str(), expected.c_str());
    EXPECT_EQ(stepped, poses.size()) << "poses skipped at speed " << speed;
    EXPECT_GT(stats.back().cuts, 0u);
    EXPECT_EQ(hash, expected) << "speed " << speed;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // The node's BLAS kernels (solve/blas_kernels.hpp): what this process computes with the
  // core is compared with the node's output bit for bit.
  stc::reexec_with_native_blas_kernels(argv);
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_bag_replay_paced");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
