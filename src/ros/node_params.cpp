#include "soft_tissue_cutting/ros/node_params.hpp"

#include "soft_tissue_cutting/ros/log_text.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"

#include <cmath>
#include <stdexcept>

namespace stc {
namespace ros_io {

NodeParams read_params(const ros::NodeHandle& pnh) {
  NodeParams p;
  pnh.param<std::string>("scene", p.scene, p.scene);
  pnh.param<std::string>("frame_id", p.frame_id, p.frame_id);
  pnh.param<double>("rate", p.rate, p.rate);
  pnh.param<std::string>("scalpel_frame", p.scalpel_frame, p.scalpel_frame);
  std::string backend;  // empty: the scene's
  pnh.param<std::string>("backend", backend, backend);
  pnh.param<double>("max_pose_jump", p.max_pose_jump, p.max_pose_jump);
  pnh.param<int>("pose_rearm_count", p.pose_rearm_count, p.pose_rearm_count);
  pnh.param<bool>("every_pose", p.every_pose, p.every_pose);
  pnh.param<double>("display_rate", p.display_rate, p.display_rate);
  pnh.param<int>("max_cut_poses", p.max_cut_poses, p.max_cut_poses);
  pnh.param<double>("max_cut_length", p.max_cut_length, p.max_cut_length);
  pnh.param<std::string>("parent_frame", p.parent_frame, p.parent_frame);
  pnh.param<std::string>("wrench_frame", p.wrench_frame, p.wrench_frame);
  if (p.wrench_frame != "tissue" && p.wrench_frame != "blade")
    throw std::runtime_error("~wrench_frame must be tissue or blade, not '" +
                             shorten(p.wrench_frame) + "'");
  if (pnh.hasParam("parent_transform") &&
      (!pnh.getParam("parent_transform", p.parent_transform) || p.parent_transform.size() != 7))
    throw std::runtime_error("~parent_transform must be a list of 7 numbers: x y z qx qy qz qw");
  const auto& v = p.parent_transform;
  const std::string problem =
      pose_problem(Vec3(v[0], v[1], v[2]), Eigen::Vector4d(v[3], v[4], v[5], v[6]));
  if (!problem.empty()) throw std::runtime_error("~parent_transform: " + problem);
  if (!(p.rate > 0) || !std::isfinite(p.rate))
    throw std::runtime_error("~rate must be a positive number of steps per second");
  if (!(p.max_pose_jump > 0)) throw std::runtime_error("~max_pose_jump must be positive (m)");
  if (p.pose_rearm_count < 1) throw std::runtime_error("~pose_rearm_count must be at least 1");
  if (!(p.display_rate > 0)) throw std::runtime_error("~display_rate must be positive (Hz)");
  if (p.max_cut_poses < 2) throw std::runtime_error("~max_cut_poses must be at least 2");
  if (!(p.max_cut_length > 0)) throw std::runtime_error("~max_cut_length must be positive (m)");
  if (!backend.empty()) {
    p.backend = parse_backend(backend);
    if (!p.backend)
      throw std::runtime_error(std::string("~backend must be ") + kBackendChoices + ", not '" +
                               shorten(backend) + "'");
  }
  p.frame_id = strip_slash(p.frame_id);
  if (p.frame_id.empty()) throw std::runtime_error("~frame_id must not be empty");
  return p;
}

Scene load_scene_param(const std::string& scene) { return load_scene(scene); }

std::string strip_slash(std::string frame) {
  if (!frame.empty() && frame[0] == '/') frame.erase(0, 1);
  return frame;
}

}  // namespace ros_io
}  // namespace stc
