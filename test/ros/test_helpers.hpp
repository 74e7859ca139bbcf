// Small helpers shared by the rostests (header-only: each rostest is one .cpp file).
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <soft_tissue_cutting/SimStats.h>
#include <visualization_msgs/Marker.h>

#include <array>
#include <cstring>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace tissue_test {

// Spins (the global queue) until pred() holds or timeout seconds pass.
inline bool spin_until(const std::function<bool()>& pred, double timeout) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end) {
    ros::spinOnce();
    if (pred()) return true;
    ros::WallDuration(0.005).sleep();
  }
  ros::spinOnce();
  return pred();
}

inline void spin_for(double seconds) {
  spin_until([] { return false; }, seconds);
}

// The /scalpel/pose messages of a bag (test/bags/, scripts/record_test_bag.sh), in order.
inline std::vector<geometry_msgs::PoseStamped> read_scalpel_poses(const std::string& path) {
  std::vector<geometry_msgs::PoseStamped> poses;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m :
       rosbag::View(bag, rosbag::TopicQuery(std::vector<std::string>{"/scalpel/pose"})))
    if (auto p = m.instantiate<geometry_msgs::PoseStamped>()) poses.push_back(*p);
  return poses;
}

// Did a step from stats[from] on use the pose stamped `stamp` (~stats scalpel_stamp)?
inline bool stepped_on(const std::vector<soft_tissue_cutting::SimStats>& stats, size_t from,
                       const ros::Time& stamp) {
  for (size_t k = from; k < stats.size(); ++k)
    if (stats[k].scalpel_stamp == stamp) return true;
  return false;
}

// Lockstep replay: publishes `pose` and spins until a step has used it: a ~stats in `stats`
// (appended by the caller's subscription) whose scalpel_stamp is the pose's stamp. The node's
// loop samples the latest pose on its own clock, so a replay at the recorded pace would feed a
// different pose sequence each time (a pose that arrived with the next one is never stepped on);
// in lockstep every replay feeds the bag's exact sequence, each pose held for one step or more,
// which the simulation makes no difference (a still blade changes nothing). Counting steps
// stamped after the publish does not prove the pose arrived: on a loaded machine its delivery
// can outlast several steps. The poses' stamps must be distinct and non-zero. False when no step
// used the pose within `timeout` (the node stopped stepping, or dropped the pose).
inline bool publish_in_lockstep(const ros::Publisher& pub, const geometry_msgs::PoseStamped& pose,
                                const std::vector<soft_tissue_cutting::SimStats>& stats,
                                double timeout = 5.0) {
  if (pose.header.stamp.isZero()) return false;
  const size_t seen = stats.size();
  pub.publish(pose);  // original (old) stamps: never a reason to drop
  return spin_until([&] { return stepped_on(stats, seen, pose.header.stamp); }, timeout);
}

struct TriangleSoup {
  int triangles = 0;
  int vertices = 0;   // distinct positions
  int bad_edges = 0;  // undirected edges not used exactly twice in opposite directions
};

// Welds a TRIANGLE_LIST's points by exact coordinates and checks that it is closed and
// consistently oriented: every edge used twice, once in each direction.
inline TriangleSoup analyse(const visualization_msgs::Marker& m) {
  TriangleSoup out;
  std::map<std::array<double, 3>, int> ids;
  auto id = [&ids](const geometry_msgs::Point& p) {
    return ids.emplace(std::array<double, 3>{p.x, p.y, p.z}, static_cast<int>(ids.size()))
        .first->second;
  };
  std::map<std::pair<int, int>, int> directed;
  out.triangles = static_cast<int>(m.points.size() / 3);
  for (size_t i = 0; i + 2 < m.points.size(); i += 3) {
    const int v[3] = {id(m.points[i]), id(m.points[i + 1]), id(m.points[i + 2])};
    for (int k = 0; k < 3; ++k) ++directed[{v[k], v[(k + 1) % 3]}];
  }
  out.vertices = static_cast<int>(ids.size());
  for (const auto& [e, n] : directed) {
    auto back = directed.find({e.second, e.first});
    if (n != 1 || back == directed.end() || back->second != 1) ++out.bad_edges;
  }
  return out;
}

// Bit-for-bit equality of two point lists.
inline bool same_points(const visualization_msgs::Marker& a, const visualization_msgs::Marker& b) {
  if (a.points.size() != b.points.size()) return false;
  for (size_t i = 0; i < a.points.size(); ++i) {
    const double pa[3] = {a.points[i].x, a.points[i].y, a.points[i].z};
    const double pb[3] = {b.points[i].x, b.points[i].y, b.points[i].z};
    if (std::memcmp(pa, pb, sizeof pa) != 0) return false;
  }
  return true;
}

}  // namespace tissue_test
