// (d, follow) Replaying a committed bag of a stroke longer than the operation region
// (test/bags/thigh_follow_cut.bag: a 10 cm incision along the thigh of
// config/scenes/thigh_follow.yaml, whose 2.5 cm ball follows the blade) in lockstep with the
// node, then waiting for the node to finish the region moves and the sweeps that waited for
// them: /diagnostics reports region moves (and none failed), the `operation_region` marker's
// ball moved, the `cut_faces` marker has new cut faces along every centimetre of the stroke (the
// cut is continuous across the moves), and every number the node published (~stats,
// ~scalpel/wrench, ~surface, ~markers) is finite. Prints the stroke length, the moves, the cut
// faces per centimetre and the time the replay took.
#include "test_helpers.hpp"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/WrenchStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/SimStats.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

using tissue_test::spin_until;

namespace {

bool finite(const geometry_msgs::Point& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

struct Fixture : testing::Test {
  ros::NodeHandle nh;
  ros::Publisher pose_pub;
  ros::Subscriber wrench_sub, stats_sub, markers_sub, surface_sub, diag_sub;
  std::vector<geometry_msgs::PoseStamped> poses;
  std::vector<soft_tissue_cutting::SimStats> stats;
  visualization_msgs::Marker cut_faces;              // the latest `cut_faces` marker
  std::vector<geometry_msgs::Point> region_centres;  // each distinct ball the marker showed
  std::map<std::string, std::string> diagnostics;    // the latest `tissue: simulation` values
  int diagnostics_seen = 0;
  std::vector<std::string> non_finite;  // what was not finite, where

  void SetUp() override {
    std::string path;
    ASSERT_TRUE(ros::param::get("~bag", path));
    poses = tissue_test::read_scalpel_poses(path);
    ASSERT_GT(poses.size(), 100u) << "no scalpel poses in " << path;

    pose_pub = nh.advertise<geometry_msgs::PoseStamped>("/scalpel/pose", 100);
    wrench_sub = nh.subscribe<geometry_msgs::WrenchStamped>(
        "/tissue/scalpel/wrench", 1000, [this](const geometry_msgs::WrenchStamped::ConstPtr& w) {
          const auto& f = w->wrench.force;
          const auto& m = w->wrench.torque;
          for (double v : {f.x, f.y, f.z, m.x, m.y, m.z})
            if (!std::isfinite(v)) non_finite.push_back("~scalpel/wrench");
        });
    stats_sub = nh.subscribe<soft_tissue_cutting::SimStats>(
        "/tissue/stats", 1000, [this](const soft_tissue_cutting::SimStats::ConstPtr& s) {
          stats.push_back(*s);
          for (double v : {s->residual, s->contact_force, s->collision_ms, s->cutting_ms,
                           s->assembly_ms, s->solve_ms, s->recovery_ms, s->step_ms, s->rate_hz})
            if (!std::isfinite(v)) non_finite.push_back("~stats");
        });
    surface_sub = nh.subscribe<visualization_msgs::Marker>(
        "/tissue/surface", 10, [this](const visualization_msgs::Marker::ConstPtr& m) {
          for (const auto& p : m->points)
            if (!finite(p)) {
              non_finite.push_back("~surface");
              break;
            }
        });
    markers_sub = nh.subscribe<visualization_msgs::MarkerArray>(
        "/tissue/markers", 100, [this](const visualization_msgs::MarkerArray::ConstPtr& a) {
          for (const auto& m : a->markers) {
            for (const auto& p : m.points)
              if (!finite(p)) {
                non_finite.push_back("~markers " + m.ns);
                break;
              }
            if (m.ns == "cut_faces") cut_faces = m;
            if (m.ns == "operation_region" && !m.points.empty()) {
              // The outline is three circles round the centre: their mean is the centre.
              geometry_msgs::Point c;
              for (const auto& p : m.points) c.x += p.x, c.y += p.y, c.z += p.z;
              c.x /= m.points.size(), c.y /= m.points.size(), c.z /= m.points.size();
              const auto& last = region_centres;
              if (last.empty() ||
                  std::hypot(last.back().x - c.x, last.back().y - c.y, last.back().z - c.z) > 1e-6)
                region_centres.push_back(c);
            }
          }
        });
    diag_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
          for (const auto& s : a->status)
            if (s.name.find("simulation") != std::string::npos) {
              for (const auto& kv : s.values) diagnostics[kv.key] = kv.value;
              ++diagnostics_seen;
            }
        });
    ASSERT_TRUE(ros::service::waitForService("/tissue/reset", ros::Duration(30)));
    ASSERT_TRUE(spin_until([this] { return pose_pub.getNumSubscribers() > 0; }, 10.0));
    ASSERT_TRUE(spin_until([this] { return !region_centres.empty(); }, 10.0))
        << "no operation_region marker";
  }

  int diagnostic_int(const std::string& key) {
    const auto it = diagnostics.find(key);
    return it == diagnostics.end() ? -1 : std::atoi(it->second.c_str());
  }
};

}  // namespace

TEST_F(Fixture, StrokeLongerThanTheRegionCutsEndToEnd) {
  const ros::WallTime start = ros::WallTime::now();
  for (const auto& pose : poses)
    ASSERT_TRUE(tissue_test::publish_in_lockstep(pose_pub, pose, stats))
        << "the node stopped stepping";
  const double replay_s = (ros::WallTime::now() - start).toSec();
  // Online the cut lags the blade by a move: wait until no move runs (two /diagnostics
  // reports after the last pose say so) and neither the cut nor the ball has changed for 1.5 s.
  const int reports = diagnostics_seen;
  unsigned split = 0;
  size_t balls = 0;
  ros::WallTime changed = ros::WallTime::now();
  EXPECT_TRUE(spin_until(
      [&] {
        if (!stats.empty() &&
            (stats.back().tets_split != split || region_centres.size() != balls)) {
          split = stats.back().tets_split;
          balls = region_centres.size();
          changed = ros::WallTime::now();
        }
        const std::string& moving = diagnostics["region moving"];
        return diagnostics_seen >= reports + 2 && (moving == "False" || moving == "false") &&
               diagnostics["sweeps waiting"] == "0" &&
               (ros::WallTime::now() - changed).toSec() > 1.5;
      },
      30.0))
      << "the region kept moving (region moving: " << diagnostics["region moving"]
      << ", sweeps waiting: " << diagnostics["sweeps waiting"] << ")";
  EXPECT_EQ(diagnostics["cut lag (m)"], "0");  // every sweep cut: the cut reached the blade
  const double total_s = (ros::WallTime::now() - start).toSec();

  // The stroke: the poses at the deepest x (the edge points radially out, +x; the draw along z).
  double x_in = 1e9;
  for (const auto& p : poses) x_in = std::min(x_in, p.pose.position.x);
  double z0 = 1e9, z1 = -1e9;
  for (const auto& p : poses)
    if (p.pose.position.x < x_in + 1e-4) {
      z0 = std::min(z0, p.pose.position.z);
      z1 = std::max(z1, p.pose.position.z);
    }
  const double stroke = z1 - z0;
  // Cut faces (deformed; the blade plane y = 0.003, the edge from x_in out 2 cm) per
  // centimetre of the stroke.
  const int bins = static_cast<int>(std::lround(stroke / 0.01));
  const double width = stroke / std::max(bins, 1);  // ~1 cm
  std::vector<int> per_cm(std::max(bins, 0), 0);
  ASSERT_EQ(cut_faces.action, visualization_msgs::Marker::ADD) << "no cut_faces at all";
  for (size_t i = 0; i + 2 < cut_faces.points.size(); i += 3) {
    const auto& a = cut_faces.points[i];
    const auto& b = cut_faces.points[i + 1];
    const auto& c = cut_faces.points[i + 2];
    const double x = (a.x + b.x + c.x) / 3, y = (a.y + b.y + c.y) / 3, z = (a.z + b.z + c.z) / 3;
    const int bin = static_cast<int>(std::floor((z - z0) / width));
    if (std::abs(y - 0.003) < 0.01 && x > x_in - 0.005 && x < x_in + 0.025 && bin >= 0 &&
        bin < bins)
      ++per_cm[bin];
  }
  std::string counts;
  for (int n : per_cm) counts += " " + std::to_string(n);
  ASSERT_FALSE(stats.empty());
  const auto& last = stats.back();
  std::printf(
      "[bag_replay_follow] %zu poses, stroke %.1f cm; replay %.1f s, until settled %.1f s; "
      "region moves %d (failed %d; diagnostics), %zu balls shown; cuts %u, tets_split %u, "
      "tets %u; %zu cut faces shown, per cm of the stroke:%s\n",
      poses.size(), 100 * stroke, replay_s, total_s, diagnostic_int("region moves"),
      diagnostic_int("region moves failed"), region_centres.size(), last.cuts, last.tets_split,
      last.tets, cut_faces.points.size() / 3, counts.c_str());

  EXPECT_GE(stroke, 0.095) << "the bag's stroke must be ~10 cm";
  EXPECT_GE(diagnostic_int("region moves"), 2);
  EXPECT_EQ(diagnostic_int("region moves failed"), 0);
  EXPECT_GE(region_centres.size(), 3u) << "the operation_region marker must show the ball moving";
  EXPECT_GT(last.tets_split, 0u);
  ASSERT_EQ(per_cm.size(), static_cast<size_t>(bins));
  for (int k = 0; k < bins; ++k)
    EXPECT_GE(per_cm[k], 1) << "no cut faces in centimetre " << k << " of the stroke";
  EXPECT_TRUE(non_finite.empty()) << non_finite.size() << " non-finite outputs, the first on "
                                  << non_finite.front();
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_bag_replay_follow");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
