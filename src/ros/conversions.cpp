#include "soft_tissue_cutting/ros/conversions.hpp"

#include <cmath>

namespace stc {
namespace ros_io {

BladePose to_blade_pose(const geometry_msgs::Pose& pose, double t) {
  BladePose b;
  b.t = t;
  b.position = Vec3(pose.position.x, pose.position.y, pose.position.z);
  b.orientation = Eigen::Quaterniond(pose.orientation.w, pose.orientation.x, pose.orientation.y,
                                     pose.orientation.z);
  b.orientation.normalize();
  return b;
}

geometry_msgs::Pose to_pose_msg(const BladePose& b) {
  geometry_msgs::Pose p;
  p.position.x = b.position.x();
  p.position.y = b.position.y();
  p.position.z = b.position.z();
  p.orientation.x = b.orientation.x();
  p.orientation.y = b.orientation.y();
  p.orientation.z = b.orientation.z();
  p.orientation.w = b.orientation.w();
  return p;
}

namespace {
std::string quaternion_problem(double x, double y, double z, double w) {
  return x * x + y * y + z * z + w * w > 1e-12 ? "" : "zero quaternion";
}
}  // namespace

std::string pose_problem(const geometry_msgs::Pose& p) {
  const double v[7] = {p.position.x,    p.position.y,    p.position.z,   p.orientation.x,
                       p.orientation.y, p.orientation.z, p.orientation.w};
  for (double x : v)
    if (!std::isfinite(x)) return "not finite (NaN/Inf)";
  return quaternion_problem(v[3], v[4], v[5], v[6]);
}

std::string pose_problem(const BladePose& b) {
  if (!b.position.allFinite() || !b.orientation.coeffs().allFinite()) return "not finite (NaN/Inf)";
  const Eigen::Vector4d q = b.orientation.coeffs();
  return quaternion_problem(q[0], q[1], q[2], q[3]);
}

soft_tissue_cutting::SimStats to_stats_msg(const StepStats& s, const ModelCounts& c,
                                           const std::string& backend, const std::string& renderer,
                                           double rate_hz) {
  soft_tissue_cutting::SimStats m;
  m.step = s.step;
  m.backend = backend;
  m.renderer = renderer;
  m.nodes = static_cast<uint32_t>(c.nodes);
  m.tets = static_cast<uint32_t>(c.tets);
  m.dof_operation = static_cast<uint32_t>(c.dof_operation);
  m.nodes_interface = static_cast<uint32_t>(c.nodes_interface);
  m.nodes_surface_condensed = static_cast<uint32_t>(c.nodes_surface_condensed);
  m.nodes_interior_condensed = static_cast<uint32_t>(c.nodes_interior_condensed);
  m.cuts = static_cast<uint32_t>(c.cuts);
  m.tets_split = static_cast<uint32_t>(c.tets_split);
  m.cg_iterations = static_cast<uint32_t>(s.cg_iterations);
  m.residual = s.residual;
  m.converged = s.converged;
  m.in_contact = s.in_contact;
  m.cutting = s.cutting;
  m.contact_force = s.contact_force.norm();
  m.collision_ms = s.collision_ms;
  m.cutting_ms = s.cutting_ms;
  m.assembly_ms = s.assembly_ms;
  m.solve_ms = s.solve_ms;
  m.recovery_ms = s.recovery_ms;
  m.step_ms = s.step_ms;
  m.rate_hz = rate_hz;
  return m;
}

geometry_msgs::WrenchStamped to_wrench_msg(const StepStats& s,
                                           const std::optional<BladePose>& blade_axes) {
  Vec3 force = s.contact_force, torque = s.contact_torque;
  if (blade_axes) {
    const Eigen::Quaterniond to_blade = blade_axes->orientation.normalized().conjugate();
    force = to_blade * force;
    torque = to_blade * torque;
  }
  geometry_msgs::WrenchStamped w;
  w.wrench.force.x = force.x();
  w.wrench.force.y = force.y();
  w.wrench.force.z = force.z();
  w.wrench.torque.x = torque.x();
  w.wrench.torque.y = torque.y();
  w.wrench.torque.z = torque.z();
  return w;
}

}  // namespace ros_io
}  // namespace stc
