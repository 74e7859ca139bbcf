// tissue_ros conversions without a master: pose round trips, the one pose check, SimStats and
// wrench filling, shortened echoes.
#include "soft_tissue_cutting/ros/conversions.hpp"
#include "soft_tissue_cutting/ros/log_text.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace stc::ros_io {
namespace {

geometry_msgs::Pose pose(double x, double y, double z, double qx, double qy, double qz, double qw) {
  geometry_msgs::Pose p;
  p.position.x = x;
  p.position.y = y;
  p.position.z = z;
  p.orientation.x = qx;
  p.orientation.y = qy;
  p.orientation.z = qz;
  p.orientation.w = qw;
  return p;
}

TEST(Conversions, PoseRoundTripNormalisesTheQuaternion) {
  const geometry_msgs::Pose in = pose(0.1, -0.2, 0.3, 0.0, 0.0, 2.0, 2.0);
  const BladePose b = to_blade_pose(in, 1.5);
  EXPECT_EQ(b.t, 1.5);
  EXPECT_EQ(b.position, Vec3(0.1, -0.2, 0.3));
  EXPECT_NEAR(b.orientation.norm(), 1.0, 1e-15);
  EXPECT_NEAR(b.orientation.z(), std::sqrt(0.5), 1e-15);
  const geometry_msgs::Pose back = to_pose_msg(b);
  EXPECT_EQ(back.position.x, 0.1);
  EXPECT_EQ(back.position.y, -0.2);
  EXPECT_EQ(back.position.z, 0.3);
  EXPECT_NEAR(back.orientation.w, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(back.orientation.x, 0.0, 1e-15);
  // Unit input comes back bit for bit.
  const geometry_msgs::Pose unit = pose(1, 2, 3, 0, 0, 0, 1);
  const geometry_msgs::Pose again = to_pose_msg(to_blade_pose(unit, 0));
  EXPECT_EQ(again.orientation.w, 1.0);
  EXPECT_EQ(again.position.z, 3.0);
}

TEST(Conversions, PoseProblemNamesNanInfAndZeroQuaternion) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(pose_problem(pose(0, 0, 0, 0, 0, 0, 1)), "");
  EXPECT_EQ(pose_problem(pose(nan, 0, 0, 0, 0, 0, 1)), "not finite (NaN/Inf)");
  EXPECT_EQ(pose_problem(pose(0, inf, 0, 0, 0, 0, 1)), "not finite (NaN/Inf)");
  EXPECT_EQ(pose_problem(pose(0, 0, 0, nan, 0, 0, 1)), "not finite (NaN/Inf)");
  EXPECT_EQ(pose_problem(pose(0, 0, 0, 0, 0, 0, 0)), "zero quaternion");
  EXPECT_EQ(pose_problem(pose(1e300, 0, 0, 0, 0, 0, 1)), "");  // finite: the gate judges it
  BladePose b;
  EXPECT_EQ(pose_problem(b), "");
  b.orientation = Eigen::Quaterniond(0, 0, 0, 0);
  EXPECT_EQ(pose_problem(b), "zero quaternion");
  b.position.x() = nan;
  EXPECT_EQ(pose_problem(b), "not finite (NaN/Inf)");
}

TEST(Conversions, SimStatsCarriesEveryField) {
  StepStats s;
  s.step = 42;
  s.in_contact = true;
  s.cutting = true;
  s.contact_force = Vec3(3, 4, 0);
  s.cg_iterations = 17;
  s.residual = 1e-11;
  s.converged = false;
  s.collision_ms = 0.5;
  s.cutting_ms = 1.5;
  s.assembly_ms = 2.5;
  s.solve_ms = 3.5;
  s.recovery_ms = 4.5;
  s.step_ms = 12.5;
  ModelCounts c;
  c.nodes = 100;
  c.tets = 300;
  c.dof_operation = 90;
  c.nodes_interface = 11;
  c.nodes_surface_condensed = 12;
  c.nodes_interior_condensed = 13;
  c.cuts = 4;
  c.tets_split = 25;
  const soft_tissue_cutting::SimStats m = to_stats_msg(s, c, "gl", "llvmpipe", 97.5);
  EXPECT_EQ(m.step, 42u);
  EXPECT_EQ(m.backend, "gl");
  EXPECT_EQ(m.renderer, "llvmpipe");
  EXPECT_EQ(m.nodes, 100u);
  EXPECT_EQ(m.tets, 300u);
  EXPECT_EQ(m.dof_operation, 90u);
  EXPECT_EQ(m.nodes_interface, 11u);
  EXPECT_EQ(m.nodes_surface_condensed, 12u);
  EXPECT_EQ(m.nodes_interior_condensed, 13u);
  EXPECT_EQ(m.cuts, 4u);
  EXPECT_EQ(m.tets_split, 25u);
  EXPECT_EQ(m.cg_iterations, 17u);
  EXPECT_EQ(m.residual, 1e-11);
  EXPECT_FALSE(m.converged);
  EXPECT_TRUE(m.in_contact);
  EXPECT_TRUE(m.cutting);
  EXPECT_DOUBLE_EQ(m.contact_force, 5.0);
  EXPECT_EQ(m.collision_ms, 0.5);
  EXPECT_EQ(m.cutting_ms, 1.5);
  EXPECT_EQ(m.assembly_ms, 2.5);
  EXPECT_EQ(m.solve_ms, 3.5);
  EXPECT_EQ(m.recovery_ms, 4.5);
  EXPECT_EQ(m.step_ms, 12.5);
  EXPECT_EQ(m.rate_hz, 97.5);
}

TEST(Conversions, WrenchIsTheContactForceWithZeroTorque) {
  StepStats s;
  s.contact_force = Vec3(0.1, -0.2, 0.3);
  const geometry_msgs::WrenchStamped w = to_wrench_msg(s);
  EXPECT_EQ(w.wrench.force.x, 0.1);
  EXPECT_EQ(w.wrench.force.y, -0.2);
  EXPECT_EQ(w.wrench.force.z, 0.3);
  EXPECT_EQ(w.wrench.torque.x, 0.0);
  EXPECT_EQ(w.wrench.torque.z, 0.0);
}

TEST(LogText, LongStringsAreShortenedWithTheirSize) {
  EXPECT_EQ(shorten("frame"), "frame");
  const std::string big(1 << 20, 'a');
  const std::string s = shorten(big);
  EXPECT_EQ(s.size(), kMaxEchoedChars + std::string("... (1048576 bytes)").size());
  EXPECT_EQ(s.substr(kMaxEchoedChars), "... (1048576 bytes)");
  EXPECT_EQ(shorten(std::string(kMaxEchoedChars, 'b')).size(), kMaxEchoedChars);
}

}  // namespace
}  // namespace stc::ros_io
