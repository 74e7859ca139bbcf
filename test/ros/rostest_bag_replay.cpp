// (d) Replaying a committed bag of scalpel poses (read with the rosbag C++ API, published on
// /scalpel/pose in lockstep with the node's steps, original stamps kept): the wrench rises before
// the cut begins and carries a torque about the tip, ~markers shows the held nodes (`contact`)
// while pressing, the surface gains cut faces, and two replays (with ~reset between) end in the
// same mesh hash (latched std_msgs/String /tissue/mesh_hash). The achieved rate is printed.
#include "test_helpers.hpp"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/SimStats.h>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using tissue_test::spin_for;
using tissue_test::spin_until;

namespace {

struct Replay {
  std::vector<std::pair<ros::Time, double>> force;  // |F| per step
  std::vector<soft_tissue_cutting::SimStats> stats;
  bool cut_faces_shown = false;
  bool contact_shown = false;       // a `contact` marker with held nodes while pressing
  double max_torque = 0;            // N m, about the blade tip
  bool torque_within_blade = true;  // |torque| <= |force| x blade length
  std::string final_hash;
};

struct Fixture : testing::Test {
  ros::NodeHandle nh;
  ros::Publisher pose_pub;
  ros::Subscriber wrench_sub, stats_sub, hash_sub, markers_sub;
  std::vector<geometry_msgs::PoseStamped> poses;
  Replay* current = nullptr;
  std::string hash;

  void SetUp() override {
    std::string path;
    ASSERT_TRUE(ros::param::get("~bag", path));
    poses = tissue_test::read_scalpel_poses(path);
    ASSERT_GT(poses.size(), 50u) << "no scalpel poses in " << path;

    pose_pub = nh.advertise<geometry_msgs::PoseStamped>("/scalpel/pose", 100);
    wrench_sub = nh.subscribe<geometry_msgs::WrenchStamped>(
        "/tissue/scalpel/wrench", 1000, [this](const geometry_msgs::WrenchStamped::ConstPtr& w) {
          if (!current) return;
          const auto& f = w->wrench.force;
          const auto& m = w->wrench.torque;
          const double force = std::sqrt(f.x * f.x + f.y * f.y + f.z * f.z);
          const double torque = std::sqrt(m.x * m.x + m.y * m.y + m.z * m.z);
          current->force.emplace_back(w->header.stamp, force);
          current->max_torque = std::max(current->max_torque, torque);
          // The held nodes lie within a blade length (the thigh's 2 cm) of the tip.
          current->torque_within_blade &= std::isfinite(torque) && torque <= 0.02 * force + 1e-12;
        });
    stats_sub = nh.subscribe<soft_tissue_cutting::SimStats>(
        "/tissue/stats", 1000, [this](const soft_tissue_cutting::SimStats::ConstPtr& s) {
          if (current) current->stats.push_back(*s);
        });
    hash_sub = nh.subscribe<std_msgs::String>(
        "/tissue/mesh_hash", 10, [this](const std_msgs::String::ConstPtr& h) { hash = h->data; });
    markers_sub = nh.subscribe<visualization_msgs::MarkerArray>(
        "/tissue/markers", 100, [this](const visualization_msgs::MarkerArray::ConstPtr& a) {
          if (!current) return;
          for (const auto& m : a->markers)
            if (m.ns == "cut_faces" && m.action == visualization_msgs::Marker::ADD &&
                !m.points.empty())
              current->cut_faces_shown = true;
            else if (m.ns == "contact" && m.action == visualization_msgs::Marker::ADD &&
                     !m.points.empty())
              current->contact_shown = true;
        });
    ASSERT_TRUE(ros::service::waitForService("/tissue/reset", ros::Duration(20)));
    ASSERT_TRUE(spin_until([this] { return pose_pub.getNumSubscribers() > 0; }, 10.0));
  }

  void replay(Replay* out, std::string* initial_hash) {
    std_srvs::Trigger t;
    ASSERT_TRUE(ros::service::call("/tissue/reset", t));
    spin_for(1.2);  // the post-reset hash arrives
    *initial_hash = hash;
    current = out;
    // Lockstep (tissue_test::publish_in_lockstep): every replay feeds the bag's exact sequence.
    for (size_t i = 0; i < poses.size(); ++i)
      ASSERT_TRUE(tissue_test::publish_in_lockstep(pose_pub, poses[i], out->stats))
          << "the node stopped stepping";
    spin_for(1.5);
    current = nullptr;
    out->final_hash = hash;
  }
};

}  // namespace

TEST_F(Fixture, ReplayPressesThenCutsAndIsRepeatable) {
  Replay first, second;
  std::string initial1, initial2;
  replay(&first, &initial1);
  replay(&second, &initial2);

  for (const Replay* r : {&first, &second}) {
    ASSERT_FALSE(r->stats.empty());
    std::vector<double> rates;
    for (const auto& s : r->stats) rates.push_back(s.rate_hz);
    std::nth_element(rates.begin(), rates.begin() + rates.size() / 2, rates.end());
    const auto& last = r->stats.back();
    std::printf(
        "[bag_replay] %zu poses replayed; %zu steps, median rate %.1f Hz; cuts %u, "
        "tets_split %u, tets %u; hash %s\n",
        poses.size(), r->stats.size(), rates[rates.size() / 2], last.cuts, last.tets_split,
        last.tets, r->final_hash.c_str());
  }

  // The wrench rises before the cut begins.
  const auto cut = std::find_if(first.stats.begin(), first.stats.end(),
                                [](const soft_tissue_cutting::SimStats& s) { return s.cuts > 0; });
  ASSERT_NE(cut, first.stats.end()) << "the replayed scalpel never cut";
  double before = 0;
  for (const auto& [stamp, f] : first.force)
    if (stamp < cut->header.stamp) before = std::max(before, f);
  ASSERT_FALSE(first.force.empty());
  EXPECT_LT(first.force.front().second, 1e-9) << "the scalpel starts outside the tissue";
  EXPECT_GT(before, 1e-3) << "no reaction force built up before the cut began";
  // The wrench carries a torque about the tip (the held nodes are off the tip), bounded by
  // the force times the blade length; rviz showed the held nodes while pressing.
  EXPECT_GT(first.max_torque, 0);
  EXPECT_TRUE(first.torque_within_blade);
  EXPECT_TRUE(first.contact_shown) << "no contact marker while pressing";

  // The surface gains cut faces.
  EXPECT_GT(first.stats.back().tets_split, 0u);
  EXPECT_TRUE(first.cut_faces_shown) << "no cut_faces triangles on ~markers";

  // Two replays, the same final mesh.
  EXPECT_EQ(initial1, initial2);
  EXPECT_NE(first.final_hash, initial1) << "the mesh did not change";
  EXPECT_EQ(first.final_hash, second.final_hash);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_bag_replay");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
