// Message conversion between the ROS-free core and ROS messages (no physics here).
#pragma once

#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/WrenchStamped.h>
#include <soft_tissue_cutting/SimStats.h>

#include <optional>
#include <string>

namespace stc {
namespace ros_io {

// geometry_msgs/Pose <-> BladePose (scene frame). The orientation is normalised on the way in.
BladePose to_blade_pose(const geometry_msgs::Pose& pose, double t);
geometry_msgs::Pose to_pose_msg(const BladePose& pose);

// Why `pose` cannot be a blade pose: "not finite (NaN/Inf)", "zero quaternion", or "" when it
// can. One check for the topic, tf2 and ~cut inputs.
std::string pose_problem(const geometry_msgs::Pose& pose);
std::string pose_problem(const BladePose& pose);

// One step's SimStats: StepStats + sizes of the current state + backend in use.
soft_tissue_cutting::SimStats to_stats_msg(const StepStats& step, const ModelCounts& counts,
                                           const std::string& backend, const std::string& renderer,
                                           double rate_hz);

// Force and torque about the blade tip on the blade; in the tissue frame, or in the blade's
// axes (x along the edge, y its normal) when `blade_axes` gives the blade pose.
geometry_msgs::WrenchStamped to_wrench_msg(const StepStats& step,
                                           const std::optional<BladePose>& blade_axes = {});

}  // namespace ros_io
}  // namespace stc
