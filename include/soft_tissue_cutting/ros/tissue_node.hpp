// tissue_node: the ROS 1 face of the simulation (SPEC section 5). Thin: all physics is in
// stc::Simulation; this class owns the loop thread, the topics, services and parameters.
//
// Threads: the simulation loop runs in its own std::thread at ~rate; ROS callbacks (pose
// input, services, dynamic_reconfigure) run on an AsyncSpinner. `sim_mutex_` guards the
// Simulation; the pose callback only touches PoseInput (its own mutex), so it never waits for
// a step. Surface and marker messages are published while holding `sim_mutex_`, so their
// order on the wire is the order of the states they show.
#pragma once

#include "soft_tissue_cutting/ros/pose_input.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/Cut.h>
#include <soft_tissue_cutting/SaveMesh.h>
#include <soft_tissue_cutting/TissueConfig.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace stc {
namespace ros_io {

struct NodeParams {
  std::string scene = "thigh";
  std::string frame_id = "tissue";
  double rate = 100.0;
  std::string scalpel_frame;  // empty: poses come from the scalpel/pose topic
  std::string backend;        // empty: the scene's solver.backend
  double max_pose_jump = 0.05;  // m
  double display_rate = 30.0;   // Hz, upper limit for ~surface / ~markers
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

class TissueNode {
 public:
  TissueNode(ros::NodeHandle nh, ros::NodeHandle pnh, NodeParams params,
             std::unique_ptr<Simulation> sim);
  ~TissueNode();
  TissueNode(const TissueNode&) = delete;
  TissueNode& operator=(const TissueNode&) = delete;

  void start();  // publishes the initial state, starts the loop thread
  void stop();   // joins the loop thread

 private:
  void loop();
  std::optional<BladePose> current_blade();  // topic or tf2 input, gated
  bool to_scene_frame(const geometry_msgs::PoseStamped& in, geometry_msgs::Pose* out,
                      std::string* why) const;
  void on_pose(const geometry_msgs::PoseStamped::ConstPtr& msg);
  // Publish ~surface, ~markers and ~mesh_hash from the current state. Caller holds sim_mutex_.
  void publish_surface_locked(const ros::Time& stamp);
  void publish_markers_locked(const ros::Time& stamp, const DeformedSurface* surface = nullptr);

  bool on_cut(soft_tissue_cutting::Cut::Request& req, soft_tissue_cutting::Cut::Response& res);
  bool on_reset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool on_set_cutting(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res);
  bool on_save(soft_tissue_cutting::SaveMesh::Request& req,
               soft_tissue_cutting::SaveMesh::Response& res);
  void on_reconfigure(soft_tissue_cutting::TissueConfig& config, uint32_t level);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  void publish_trajectory_param();

  ros::NodeHandle nh_, pnh_;
  NodeParams params_;
  std::unique_ptr<Simulation> sim_;
  std::mutex sim_mutex_;
  PoseInput pose_input_;

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::StaticTransformBroadcaster frame_broadcaster_;

  ros::Subscriber pose_sub_;
  ros::Publisher surface_pub_, markers_pub_, wrench_pub_, stats_pub_, hash_pub_;
  ros::ServiceServer cut_srv_, reset_srv_, set_cutting_srv_, save_srv_;

  boost::recursive_mutex reconfigure_mutex_;
  soft_tissue_cutting::TissueConfig config_;  // under reconfigure_mutex_
  std::unique_ptr<dynamic_reconfigure::Server<soft_tissue_cutting::TissueConfig>> reconfigure_;
  diagnostic_updater::Updater diagnostics_;

  std::thread thread_;
  std::atomic<bool> running_{false};
  std::chrono::steady_clock::time_point started_;

  // Loop bookkeeping (loop thread; read by diagnostics under stats_mutex_).
  std::mutex stats_mutex_;
  double achieved_rate_ = 0;
  bool last_converged_ = true;
  std::uint64_t steps_ = 0;

  // Display bookkeeping (under sim_mutex_).
  std::uint64_t published_version_ = 0;
  bool published_any_ = false;
  ros::WallTime last_surface_pub_, last_markers_pub_;
  std::string last_hash_;
  std::optional<BladePose> shown_blade_;  // blade in the last ~markers
  bool shown_cutting_ = false;
};

}  // namespace ros_io
}  // namespace stc
