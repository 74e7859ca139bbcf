// tissue_node's private parameters (docs/ROS.md has the table) and the ~scene loader.
#pragma once

#include "soft_tissue_cutting/scene/scene.hpp"

#include <ros/node_handle.h>

#include <string>
#include <vector>

namespace stc {
namespace ros_io {

struct NodeParams {
  std::string scene = "thigh";
  std::string frame_id = "tissue";
  double rate = 100.0;
  std::string scalpel_frame;       // empty: poses come from the scalpel/pose topic
  std::optional<Backend> backend;  // ~backend; nullopt: the scene's solver.backend
  double max_pose_jump = 0.05;     // m
  int pose_rearm_count = 20;       // consecutive jump refusals before re-arming on the newest pose
  // Step on every scalpel/pose in order, one per step (pose_input.hpp, queue_limit), instead
  // of the newest: a replayed bag cuts the same at any pace the loop keeps up with.
  bool every_pose = false;
  double display_rate = 30.0;  // Hz, upper limit for ~surface / ~markers
  // ~cut request limits: more poses, or a longer blade travel, is refused with a message.
  int max_cut_poses = 20000;
  double max_cut_length = 1.0;  // m of blade travel (cutting/blade_path)
  // If set, the node publishes ~frame_id as a static tf child of this frame (placed by
  // parent_transform: x y z qx qy qz qw), so the tissue sits in a robot's tf tree and rviz
  // has its fixed frame. Empty: someone else publishes ~frame_id.
  std::string parent_frame;
  std::vector<double> parent_transform = {0, 0, 0, 0, 0, 0, 1};
  // ~scalpel/wrench axes: "tissue" (~frame_id) or "blade" (x along the edge, y the blade
  // normal, z = x cross y; header frame ~scalpel_frame, or "scalpel" without one). The torque
  // is about the blade tip either way.
  std::string wrench_frame = "tissue";
};

// Reads the private parameters; throws std::runtime_error naming a bad one.
NodeParams read_params(const ros::NodeHandle& pnh);

// The scene named by ~scene: "thigh" or a YAML path. Throws std::runtime_error with a
// one-line reason naming the file.
Scene load_scene_param(const std::string& scene);

// frame without a leading '/' (tf2 frame ids have none).
std::string strip_slash(std::string frame);

}  // namespace ros_io
}  // namespace stc
