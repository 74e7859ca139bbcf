// tissue_node wiring: topics, services, parameters and threads (see tissue_node.hpp).
#include "soft_tissue_cutting/ros/tissue_node.hpp"

#include <geometry_msgs/WrenchStamped.h>
#include <soft_tissue_cutting/SimStats.h>
#include <std_msgs/String.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <stdexcept>

namespace stc {
namespace ros_io {

TissueNode::TissueNode(ros::NodeHandle nh, ros::NodeHandle pnh, NodeParams params, Scene scene,
                       SimulationOptions options, std::unique_ptr<Simulation> sim)
    : nh_(nh),
      pnh_(pnh),
      params_(std::move(params)),
      initial_scene_(std::move(scene)),
      options_(std::move(options)),
      sim_(std::move(sim)),
      pose_input_(pose_gate_settings()),
      monitor_(params_.rate, std::chrono::steady_clock::now()),
      tf_listener_(tf_buffer_),
      diagnostics_(nh_, pnh_) {
  surface_pub_ = pnh_.advertise<visualization_msgs::Marker>("surface", 1, true);
  markers_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  wrench_pub_ = pnh_.advertise<geometry_msgs::WrenchStamped>("scalpel/wrench", 10);
  stats_pub_ = pnh_.advertise<soft_tissue_cutting::SimStats>("stats", 10);
  hash_pub_ = pnh_.advertise<std_msgs::String>("mesh_hash", 1, true);
  publish_parent_frame();

  cut_srv_ = pnh_.advertiseService("cut", &TissueNode::on_cut, this);
  reset_srv_ = pnh_.advertiseService("reset", &TissueNode::on_reset, this);
  set_cutting_srv_ = pnh_.advertiseService("set_cutting", &TissueNode::on_set_cutting, this);
  save_srv_ = pnh_.advertiseService("save", &TissueNode::on_save, this);

  // dynamic_reconfigure: start from the scene's values unless a parameter was set explicitly.
  const bool has_pressure = pnh_.hasParam("cut_pressure");
  const bool has_young = pnh_.hasParam("young_modulus");
  const bool has_cutting = pnh_.hasParam("cutting_enabled");
  const bool has_guard = pnh_.hasParam("shape_guard_deg");
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<soft_tissue_cutting::TissueConfig>>(
      reconfigure_mutex_, pnh_);
  {
    boost::recursive_mutex::scoped_lock lock(reconfigure_mutex_);
    reconfigure_->getConfigDefault(config_);
    pnh_.getParam("cut_pressure", config_.cut_pressure);
    pnh_.getParam("young_modulus", config_.young_modulus);
    pnh_.getParam("cutting_enabled", config_.cutting_enabled);
    pnh_.getParam("shape_guard_deg", config_.shape_guard_deg);
    if (!has_pressure) config_.cut_pressure = sim_->scene().scalpel.cut_pressure;
    if (!has_young) config_.young_modulus = sim_->scene().material.young_modulus;
    if (!has_cutting) config_.cutting_enabled = sim_->cutting_enabled();
    if (!has_guard) config_.shape_guard_deg = sim_->scene().scalpel.shape_guard_deg;
  }
  reconfigure_->updateConfig(config_);
  reconfigure_->setCallback(
      [this](soft_tissue_cutting::TissueConfig& c, uint32_t level) { on_reconfigure(c, level); });

  remember_backend_locked();  // no other thread runs yet
  diagnostics_.setHardwareID("tissue_node/" + sim_->scene().source);
  diagnostics_.add("simulation", this, &TissueNode::diagnose);

  publish_trajectory_param();

  // ~every_pose: a burst of poses waits in the gate's queue, not in a short subscriber queue
  // that would drop the oldest.
  if (params_.scalpel_frame.empty())
    pose_sub_ =
        nh_.subscribe("scalpel/pose", params_.every_pose ? 1000 : 10, &TissueNode::on_pose, this);
  else
    ROS_INFO("tissue_node: scalpel pose from tf2 frame '%s' in '%s'", params_.scalpel_frame.c_str(),
             params_.frame_id.c_str());
}

TissueNode::~TissueNode() { stop(); }

PoseGateSettings TissueNode::pose_gate_settings() const {
  PoseGateSettings s;
  s.max_jump = params_.max_pose_jump;
  s.rearm_after = params_.pose_rearm_count;
  if (params_.every_pose) s.queue_limit = kEveryPoseQueue;
  const std::vector<Vec3>& x = initial_scene_.mesh.nodes;
  s.tissue_box.min = s.tissue_box.max = x.empty() ? Vec3::Zero() : x.front();
  for (const Vec3& p : x) {
    s.tissue_box.min = s.tissue_box.min.cwiseMin(p);
    s.tissue_box.max = s.tissue_box.max.cwiseMax(p);
  }
  return s;
}

void TissueNode::start() {
  started_ = std::chrono::steady_clock::now();
  publish_display_now();
  running_ = true;
  thread_ = std::thread(&TissueNode::loop, this);
  display_thread_ = std::thread(&TissueNode::display_thread, this);
  diagnostics_thread_ = std::thread(&TissueNode::diagnostics_thread, this);
  const ModelCounts c = sim_->counts();
  ROS_INFO("tissue_node: scene '%s', %d nodes, %d tets, backend %s, %.0f steps/s in '%s'",
           sim_->scene().source.c_str(), c.nodes, c.tets, sim_->backend().c_str(), params_.rate,
           params_.frame_id.c_str());
  if (!sim_->backend_note().empty()) ROS_WARN("tissue_node: %s", sim_->backend_note().c_str());
}

void TissueNode::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
  if (display_thread_.joinable()) display_thread_.join();
  if (diagnostics_thread_.joinable()) diagnostics_thread_.join();
  std::deque<std::shared_ptr<CutJob>> left;
  {
    std::lock_guard<std::mutex> lock(cut_mutex_);
    left.swap(queued_cuts_);
  }
  if (active_cut_) left.push_front(active_cut_);
  active_cut_.reset();
  answer_cuts(std::move(left), "the node is shutting down");
}

void TissueNode::publish_parent_frame() {
  if (params_.parent_frame.empty()) return;
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = strip_slash(params_.parent_frame);
  t.child_frame_id = params_.frame_id;
  const auto& v = params_.parent_transform;
  t.transform.translation.x = v[0];
  t.transform.translation.y = v[1];
  t.transform.translation.z = v[2];
  // read_params refused a zero quaternion (pose_problem)
  const Eigen::Quaterniond q = unit_quaternion(Eigen::Vector4d(v[3], v[4], v[5], v[6]));
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  frame_broadcaster_.sendTransform(t);
}

void TissueNode::publish_trajectory_param() {
  // The scene's scripted scalpel as a parameter ~trajectory, in the scene YAML's own format
  // (list of {t, position, orientation}); scripts/trajectory_player.py plays it for `thigh`.
  XmlRpc::XmlRpcValue list;
  list.setSize(0);
  int i = 0;
  for (const BladePose& p : initial_scene_.trajectory) {
    XmlRpc::XmlRpcValue entry, pos, ori;
    entry["t"] = p.t;
    pos.setSize(3);
    for (int k = 0; k < 3; ++k) pos[k] = p.position[k];
    ori.setSize(4);
    ori[0] = p.orientation.x();
    ori[1] = p.orientation.y();
    ori[2] = p.orientation.z();
    ori[3] = p.orientation.w();
    entry["position"] = pos;
    entry["orientation"] = ori;
    list[i++] = entry;
  }
  pnh_.setParam("trajectory", list);
}

}  // namespace ros_io
}  // namespace stc
