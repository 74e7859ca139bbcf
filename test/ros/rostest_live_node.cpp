// (e) The node stays live and honest: a long ~cut (many sweeps) is inserted in slices while
// ~stats and /diagnostics keep coming; requests over the limits are refused with a message;
// /diagnostics reports the worst step and the rate over the last second; a bad first pose
// does not disable the scalpel (re-armed after ~pose_rearm_count jumps).
#include "test_helpers.hpp"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/Cut.h>
#include <soft_tissue_cutting/SimStats.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <optional>
#include <thread>

using tissue_test::spin_for;
using tissue_test::spin_until;

namespace {

struct Fixture : testing::Test {
  ros::NodeHandle nh;
  ros::Publisher pose_pub;
  ros::Subscriber stats_sub, diag_sub, markers_sub;
  std::mutex mutex;
  std::vector<ros::WallTime> stats_times;
  std::vector<diagnostic_msgs::DiagnosticStatus> diagnostics;
  std::vector<ros::WallTime> diagnostics_times;
  std::optional<geometry_msgs::Point> blade;

  void SetUp() override {
    pose_pub = nh.advertise<geometry_msgs::PoseStamped>("/scalpel/pose", 100);
    stats_sub = nh.subscribe<soft_tissue_cutting::SimStats>(
        "/tissue/stats", 1000, [this](const soft_tissue_cutting::SimStats::ConstPtr&) {
          std::lock_guard<std::mutex> lock(mutex);
          stats_times.push_back(ros::WallTime::now());
        });
    diag_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
          std::lock_guard<std::mutex> lock(mutex);
          for (const auto& s : a->status)
            if (s.name.find("simulation") != std::string::npos) {
              diagnostics.push_back(s);
              diagnostics_times.push_back(ros::WallTime::now());
            }
        });
    markers_sub = nh.subscribe<visualization_msgs::MarkerArray>(
        "/tissue/markers", 100, [this](const visualization_msgs::MarkerArray::ConstPtr& a) {
          std::lock_guard<std::mutex> lock(mutex);
          for (const auto& m : a->markers)
            if (m.ns == "scalpel" && m.id == 0) {
              if (m.action == visualization_msgs::Marker::ADD)
                blade = m.pose.position;
              else
                blade.reset();
            }
        });
    ASSERT_TRUE(ros::service::waitForService("/tissue/reset", ros::Duration(20)));
    ASSERT_TRUE(spin_until([this] { return pose_pub.getNumSubscribers() > 0; }, 10.0));
    std_srvs::Trigger t;
    ASSERT_TRUE(ros::service::call("/tissue/reset", t));
    spin_for(0.3);
  }

  void send(double x, double y, double z) {
    geometry_msgs::PoseStamped p;
    p.header.frame_id = "tissue";
    p.pose.position.x = x;
    p.pose.position.y = y;
    p.pose.position.z = z;
    p.pose.orientation.w = 1;
    pose_pub.publish(p);
  }

  bool blade_at(double x, double y, double z, double timeout = 3.0) {
    return spin_until(
        [&] {
          std::lock_guard<std::mutex> lock(mutex);
          return blade && std::abs(blade->x - x) < 1e-9 && std::abs(blade->y - y) < 1e-9 &&
                 std::abs(blade->z - z) < 1e-9;
        },
        timeout);
  }

  std::optional<std::string> value(const diagnostic_msgs::DiagnosticStatus& s,
                                   const std::string& key) {
    for (const auto& kv : s.values)
      if (kv.key == key) return kv.value;
    return std::nullopt;
  }
};

geometry_msgs::PoseStamped pose_at(double x, double y, double z) {
  geometry_msgs::PoseStamped p;
  p.pose.position.x = x;
  p.pose.position.y = y;
  p.pose.position.z = z;
  p.pose.orientation.w = 1;
  return p;
}

// A zigzag through the thigh's operation region: `passes` strokes along z at x = 0.048, each
// a little deeper (the tip 8..16 mm in), `per_pass` poses each.
std::vector<geometry_msgs::PoseStamped> zigzag(int passes, int per_pass) {
  std::vector<geometry_msgs::PoseStamped> out;
  for (int k = 0; k < passes; ++k)
    for (int i = 0; i < per_pass; ++i) {
      const double s = static_cast<double>(i) / (per_pass - 1);
      const double z = (k % 2 == 0) ? 0.028 + 0.04 * s : 0.068 - 0.04 * s;
      out.push_back(pose_at(0.052 - 0.008 * k / std::max(1, passes - 1), -0.004 + 0.001 * k, z));
    }
  return out;
}

TEST_F(Fixture, LongCutKeepsTheLoopPublishing) {
  ros::AsyncSpinner spinner(2);  // callbacks run while the service call blocks this thread
  spinner.start();
  soft_tissue_cutting::Cut cut;
  cut.request.poses = zigzag(8, 1250);  // 10,000 poses, ~0.32 m of travel
  {
    std::lock_guard<std::mutex> lock(mutex);
    stats_times.clear();
    diagnostics.clear();
    diagnostics_times.clear();
  }
  const ros::WallTime t0 = ros::WallTime::now();
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  const ros::WallTime t1 = ros::WallTime::now();
  spinner.stop();
  const double seconds = (t1 - t0).toSec();
  EXPECT_TRUE(cut.response.success) << cut.response.message;
  EXPECT_GT(cut.response.cut_faces, 50u);
  std::lock_guard<std::mutex> lock(mutex);
  int during = 0;
  double gap = 0;
  ros::WallTime last = t0;
  for (const auto& t : stats_times)
    if (t >= t0 && t <= t1) {
      ++during;
      gap = std::max(gap, (t - last).toSec());
      last = t;
    }
  gap = std::max(gap, (t1 - last).toSec());
  int diag_during = 0;
  for (const auto& t : diagnostics_times) diag_during += (t >= t0 && t <= t1);
  std::printf(
      "[live_node] ~cut of %zu poses took %.2f s: %d ~stats (%.1f/s), longest gap "
      "%.3f s, %d /diagnostics; %u tets split, %u cut faces\n",
      cut.request.poses.size(), seconds, during, during / seconds, gap, diag_during,
      cut.response.tets_split, cut.response.cut_faces);
  // 0.35 s here since a slice's sweeps share one factorization (was > 0.5 s): still ~30 steps.
  EXPECT_GT(seconds, 0.2) << "too short to tell; the path should need many slices";
  EXPECT_GT(during, 0.3 * 100 * seconds) << "the loop must keep stepping during a long ~cut";
  // One sweep cannot be split (~0.1 s on the thigh): no gap much longer than that.
  EXPECT_LT(gap, 1.0) << "~stats stopped for a while during the ~cut";
  EXPECT_GE(diag_during, static_cast<int>(seconds) - 1) << "/diagnostics must keep coming";
}

TEST_F(Fixture, RequestsOverTheLimitsAreRefused) {
  soft_tissue_cutting::Cut cut;
  cut.request.poses.assign(20001, pose_at(0.048, 0.003, 0.03));
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  EXPECT_FALSE(cut.response.success);
  EXPECT_NE(cut.response.message.find("~max_cut_poses = 20000"), std::string::npos)
      << cut.response.message;
  cut.request.poses = {pose_at(0.048, 0.003, 0.03), pose_at(0.048, 0.003, 2.03)};
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  EXPECT_FALSE(cut.response.success);
  EXPECT_NE(cut.response.message.find("~max_cut_length"), std::string::npos)
      << cut.response.message;
}

TEST_F(Fixture, DiagnosticsReportWorstStepAndRateOverTheLastSecond) {
  ASSERT_TRUE(spin_until(
      [&] {
        std::lock_guard<std::mutex> lock(mutex);
        return diagnostics.size() >= 3;
      },
      10.0));
  std::lock_guard<std::mutex> lock(mutex);
  const auto& s = diagnostics.back();
  const auto worst = value(s, "worst step last second (ms)");
  const auto rate = value(s, "rate achieved (Hz)");
  const auto stalled = value(s, "stalled");
  ASSERT_TRUE(worst && rate && stalled);
  std::printf("[live_node] /diagnostics: level %d '%s', worst %s ms, rate %s Hz\n", s.level,
              s.message.c_str(), worst->c_str(), rate->c_str());
  EXPECT_GT(std::stod(*worst), 0.0);
  EXPECT_GT(std::stod(*rate), 50.0);
  EXPECT_LT(std::stod(*rate), 110.0);
  EXPECT_EQ(*stalled, "False");
  EXPECT_NE(s.level, diagnostic_msgs::DiagnosticStatus::ERROR) << s.message;
}

TEST_F(Fixture, BadFirstPoseIsRefusedAndJumpsReArm) {
  send(10.0, 0.0, 0.0);  // first pose after ~reset, 10 m away: refused
  spin_for(1.2);
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_FALSE(blade) << "a first pose 10 m from the tissue was accepted";
  }
  // Accepted near the tissue, then the scalpel "moves" 10 cm at once: after
  // ~pose_rearm_count = 5 consecutive jumps the node follows it again.
  send(0.10, 0.003, 0.048);
  ASSERT_TRUE(blade_at(0.10, 0.003, 0.048));
  for (int i = 0; i < 4; ++i) {
    send(0.003, 0.10, 0.048);
    spin_for(0.05);
  }
  spin_for(1.2);
  EXPECT_TRUE(blade_at(0.10, 0.003, 0.048, 0.1)) << "re-armed too early";
  send(0.003, 0.10, 0.048);
  EXPECT_TRUE(blade_at(0.003, 0.10, 0.048)) << "the node did not re-arm on the newest pose";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_live_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
