#include "soft_tissue_cutting/ros/node_params.hpp"

#include "soft_tissue_cutting/ros/log_text.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"

#include <cmath>
#include <stdexcept>

namespace stc {
namespace ros_io {

namespace {

// ~key into `value` if set; a value of the wrong type is an error naming the key (ros::param
// would silently keep the default: `_rate:=fast` ran at 100 Hz). An int is a double too.
template <typename T>
void read(const ros::NodeHandle& pnh, const char* key, T& value, const char* type) {
  if (!pnh.hasParam(key)) return;
  if (!pnh.getParam(key, value))
    throw std::runtime_error(std::string("~") + key + " must be " + type);
}

// ros::param rounds a double into an int (`_max_cut_poses:=1.5` ran with 2): only an integer
// value is an integer here.
template <>
void read<int>(const ros::NodeHandle& pnh, const char* key, int& value, const char* type) {
  if (!pnh.hasParam(key)) return;
  XmlRpc::XmlRpcValue v;
  if (pnh.getParam(key, v)) {
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
      value = static_cast<int>(v);
      return;
    }
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
      const double d = static_cast<double>(v);
      if (std::isfinite(d) && d == std::floor(d) && std::abs(d) < 2e9) {
        value = static_cast<int>(d);
        return;
      }
    }
  }
  throw std::runtime_error(std::string("~") + key + " must be " + type);
}

}  // namespace

NodeParams read_params(const ros::NodeHandle& pnh) {
  NodeParams p;
  read(pnh, "scene", p.scene, "a string (a scene YAML path or thigh)");
  read(pnh, "frame_id", p.frame_id, "a string (a tf frame)");
  read(pnh, "rate", p.rate, "a number (steps per second)");
  read(pnh, "scalpel_frame", p.scalpel_frame, "a string (a tf frame)");
  std::string backend;  // empty: the scene's
  read(pnh, "backend", backend, "a string (cpu or gl)");
  read(pnh, "max_pose_jump", p.max_pose_jump, "a number (m)");
  read(pnh, "pose_rearm_count", p.pose_rearm_count, "an integer");
  read(pnh, "every_pose", p.every_pose, "true or false");
  read(pnh, "display_rate", p.display_rate, "a number (Hz)");
  read(pnh, "max_cut_poses", p.max_cut_poses, "an integer");
  read(pnh, "max_cut_length", p.max_cut_length, "a number (m)");
  read(pnh, "parent_frame", p.parent_frame, "a string (a tf frame)");
  read(pnh, "wrench_frame", p.wrench_frame, "a string (tissue or blade)");
  {  // dynamic_reconfigure's start values (tissue_node.cpp reads them): the type only here
    double number = 0;
    bool flag = false;
    read(pnh, "cut_pressure", number, "a number (N)");
    read(pnh, "young_modulus", number, "a number (Pa)");
    read(pnh, "cutting_enabled", flag, "true or false");
    // The range dynamic_reconfigure would clamp to silently, and the scene key's (SCENE.md).
    number = 0;
    read(pnh, "shape_guard_deg", number, "a number (degrees)");
    if (!(number >= 0 && number <= kMaxShapeGuardDeg))
      throw std::runtime_error("~shape_guard_deg must be in [0, 30] (degrees)");
  }
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
