#include "soft_tissue_cutting/ros/pose_input.hpp"

#include <cstdio>

namespace stc {
namespace ros_io {

bool PoseInput::offer(const BladePose& pose, std::string* why) {
  const Eigen::Vector4d q = pose.orientation.coeffs();
  if (!pose.position.allFinite() || !q.allFinite() || q.squaredNorm() < 1e-12) {
    if (why) *why = "not finite (NaN/Inf) or zero quaternion";
    return false;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (last_) {
    const double jump = (pose.position - last_->position).norm();
    if (jump > max_jump_) {
      if (why) {
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      "jump of %.4g m from the last accepted pose exceeds ~max_pose_jump = %.4g m",
                      jump, max_jump_);
        *why = buf;
      }
      return false;
    }
  }
  last_ = pose;
  last_->orientation.normalize();
  return true;
}

std::optional<BladePose> PoseInput::latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_;
}

void PoseInput::clear() {
  std::lock_guard<std::mutex> lock(mutex_);
  last_.reset();
}

}  // namespace ros_io
}  // namespace stc
