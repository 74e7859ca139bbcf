// The one pose check of scene.hpp (pose_problem, unit_quaternion).
#include "soft_tissue_cutting/scene/scene.hpp"

namespace stc {

std::string pose_problem(const Vec3& position, const Eigen::Vector4d& q) {
  if (!position.allFinite() || !q.allFinite()) return "not finite (NaN/Inf)";
  return q.squaredNorm() > 1e-12 ? "" : "zero quaternion";
}

std::string pose_problem(const BladePose& pose) {
  return pose_problem(pose.position, pose.orientation.coeffs());  // coeffs(): x y z w
}

Eigen::Quaterniond unit_quaternion(const Eigen::Vector4d& q) {
  return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized();
}

}  // namespace stc
