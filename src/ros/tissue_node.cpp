#include "soft_tissue_cutting/ros/tissue_node.hpp"

#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/ros/conversions.hpp"
#include "soft_tissue_cutting/ros/markers.hpp"

#if __has_include("soft_tissue_cutting/scene/scene_loader.hpp")
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#define TISSUE_HAVE_SCENE_LOADER 1
#endif

#include <std_msgs/String.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <stdexcept>

namespace stc {
namespace ros_io {

NodeParams read_params(const ros::NodeHandle& pnh) {
  NodeParams p;
  pnh.param<std::string>("scene", p.scene, p.scene);
  pnh.param<std::string>("frame_id", p.frame_id, p.frame_id);
  pnh.param<double>("rate", p.rate, p.rate);
  pnh.param<std::string>("scalpel_frame", p.scalpel_frame, p.scalpel_frame);
  pnh.param<std::string>("backend", p.backend, p.backend);
  pnh.param<double>("max_pose_jump", p.max_pose_jump, p.max_pose_jump);
  pnh.param<double>("display_rate", p.display_rate, p.display_rate);
  pnh.param<std::string>("parent_frame", p.parent_frame, p.parent_frame);
  pnh.param<std::string>("wrench_frame", p.wrench_frame, p.wrench_frame);
  if (p.wrench_frame != "tissue" && p.wrench_frame != "blade")
    throw std::runtime_error("~wrench_frame must be tissue or blade, not '" + p.wrench_frame + "'");
  if (pnh.hasParam("parent_transform") &&
      (!pnh.getParam("parent_transform", p.parent_transform) || p.parent_transform.size() != 7))
    throw std::runtime_error("~parent_transform must be a list of 7 numbers: x y z qx qy qz qw");
  for (double v : p.parent_transform)
    if (!std::isfinite(v)) throw std::runtime_error("~parent_transform has a non-finite number");
  if (!(p.rate > 0) || !std::isfinite(p.rate))
    throw std::runtime_error("~rate must be a positive number of steps per second");
  if (!(p.max_pose_jump > 0))
    throw std::runtime_error("~max_pose_jump must be positive (m)");
  if (!(p.display_rate > 0)) throw std::runtime_error("~display_rate must be positive (Hz)");
  if (p.backend != "" && p.backend != "cpu" && p.backend != "gl")
    throw std::runtime_error("~backend must be cpu or gl, not '" + p.backend + "'");
  if (p.frame_id.empty()) throw std::runtime_error("~frame_id must not be empty");
  if (!p.frame_id.empty() && p.frame_id[0] == '/') p.frame_id.erase(0, 1);
  return p;
}

Scene load_scene_param(const std::string& scene) {
#ifdef TISSUE_HAVE_SCENE_LOADER
  return load_scene(scene);
#else
  if (scene == "thigh") return make_thigh_scene();
  if (!std::ifstream(scene))
    throw std::runtime_error("scene '" + scene + "': cannot open the file");
  throw std::runtime_error("scene '" + scene +
                           "': YAML scene loading is not available in this build (use thigh)");
#endif
}

namespace {

std::string strip_slash(std::string frame) {
  if (!frame.empty() && frame[0] == '/') frame.erase(0, 1);
  return frame;
}

}  // namespace

TissueNode::TissueNode(ros::NodeHandle nh, ros::NodeHandle pnh, NodeParams params,
                       std::unique_ptr<Simulation> sim)
    : nh_(nh),
      pnh_(pnh),
      params_(std::move(params)),
      sim_(std::move(sim)),
      pose_input_(params_.max_pose_jump),
      tf_listener_(tf_buffer_),
      diagnostics_(nh_, pnh_) {
  surface_pub_ = pnh_.advertise<visualization_msgs::Marker>("surface", 1, true);
  markers_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  wrench_pub_ = pnh_.advertise<geometry_msgs::WrenchStamped>("scalpel/wrench", 10);
  stats_pub_ = pnh_.advertise<soft_tissue_cutting::SimStats>("stats", 10);
  hash_pub_ = pnh_.advertise<std_msgs::String>("mesh_hash", 1, true);
  if (!params_.parent_frame.empty()) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = ros::Time::now();
    t.header.frame_id = strip_slash(params_.parent_frame);
    t.child_frame_id = params_.frame_id;
    const auto& v = params_.parent_transform;
    t.transform.translation.x = v[0];
    t.transform.translation.y = v[1];
    t.transform.translation.z = v[2];
    const double n = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (!(n > 0)) throw std::runtime_error("~parent_transform has a zero quaternion");
    t.transform.rotation.x = v[3] / n;
    t.transform.rotation.y = v[4] / n;
    t.transform.rotation.z = v[5] / n;
    t.transform.rotation.w = v[6] / n;
    frame_broadcaster_.sendTransform(t);
  }

  cut_srv_ = pnh_.advertiseService("cut", &TissueNode::on_cut, this);
  reset_srv_ = pnh_.advertiseService("reset", &TissueNode::on_reset, this);
  set_cutting_srv_ = pnh_.advertiseService("set_cutting", &TissueNode::on_set_cutting, this);
  save_srv_ = pnh_.advertiseService("save", &TissueNode::on_save, this);

  // dynamic_reconfigure: start from the scene's values unless a parameter was set explicitly.
  const bool has_pressure = pnh_.hasParam("cut_pressure");
  const bool has_young = pnh_.hasParam("young_modulus");
  const bool has_cutting = pnh_.hasParam("cutting_enabled");
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<soft_tissue_cutting::TissueConfig>>(
      reconfigure_mutex_, pnh_);
  {
    boost::recursive_mutex::scoped_lock lock(reconfigure_mutex_);
    reconfigure_->getConfigDefault(config_);
    pnh_.getParam("cut_pressure", config_.cut_pressure);
    pnh_.getParam("young_modulus", config_.young_modulus);
    pnh_.getParam("cutting_enabled", config_.cutting_enabled);
    if (!has_pressure) config_.cut_pressure = sim_->scene().scalpel.cut_pressure;
    if (!has_young) config_.young_modulus = sim_->scene().material.young_modulus;
    if (!has_cutting) config_.cutting_enabled = sim_->cutting_enabled();
  }
  reconfigure_->updateConfig(config_);
  reconfigure_->setCallback(
      [this](soft_tissue_cutting::TissueConfig& c, uint32_t level) { on_reconfigure(c, level); });

  diagnostics_.setHardwareID("tissue_node/" + sim_->scene().source);
  diagnostics_.add("simulation", this, &TissueNode::diagnose);

  publish_trajectory_param();

  if (params_.scalpel_frame.empty())
    pose_sub_ = nh_.subscribe("scalpel/pose", 10, &TissueNode::on_pose, this);
  else
    ROS_INFO("tissue_node: scalpel pose from tf2 frame '%s' in '%s'",
             params_.scalpel_frame.c_str(), params_.frame_id.c_str());
}

TissueNode::~TissueNode() { stop(); }

void TissueNode::start() {
  started_ = std::chrono::steady_clock::now();
  {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    publish_surface_locked(ros::Time::now());
  }
  running_ = true;
  thread_ = std::thread(&TissueNode::loop, this);
  const ModelCounts c = sim_->counts();
  ROS_INFO("tissue_node: scene '%s', %d nodes, %d tets, backend %s, %.0f steps/s in '%s'",
           sim_->scene().source.c_str(), c.nodes, c.tets, sim_->backend().c_str(), params_.rate,
           params_.frame_id.c_str());
  if (!sim_->backend_note().empty()) ROS_WARN("tissue_node: %s", sim_->backend_note().c_str());
}

void TissueNode::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

void TissueNode::publish_trajectory_param() {
  // The scene's scripted scalpel as a parameter ~trajectory, in the scene YAML's own format
  // (list of {t, position, orientation}); scripts/trajectory_player.py plays it for `thigh`.
  XmlRpc::XmlRpcValue list;
  list.setSize(0);
  int i = 0;
  for (const BladePose& p : sim_->scene().trajectory) {
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

bool TissueNode::to_scene_frame(const geometry_msgs::PoseStamped& in, geometry_msgs::Pose* out,
                                std::string* why) const {
  const std::string frame = strip_slash(in.header.frame_id);
  if (frame.empty() || frame == params_.frame_id) {
    *out = in.pose;
    return true;
  }
  // Latest available transform: a pose is never dropped for its stamp's age (bags are often
  // replayed without sim time).
  try {
    const geometry_msgs::TransformStamped tf =
        tf_buffer_.lookupTransform(params_.frame_id, frame, ros::Time(0));
    tf2::doTransform(in.pose, *out, tf);
    return true;
  } catch (const tf2::TransformException& e) {
    *why = "unknown frame '" + frame + "' (" + e.what() + ")";
    return false;
  }
}

void TissueNode::on_pose(const geometry_msgs::PoseStamped::ConstPtr& msg) {
  if (!is_finite_pose(msg->pose)) {
    ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel pose: NaN/Inf or zero quaternion");
    return;
  }
  geometry_msgs::Pose pose;
  std::string why;
  if (!to_scene_frame(*msg, &pose, &why)) {
    ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel pose: %s", why.c_str());
    return;
  }
  if (!pose_input_.offer(to_blade_pose(pose, 0.0), &why))
    ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel pose: %s", why.c_str());
}

std::optional<BladePose> TissueNode::current_blade() {
  if (!params_.scalpel_frame.empty()) {
    try {
      const geometry_msgs::TransformStamped tf =
          tf_buffer_.lookupTransform(params_.frame_id, params_.scalpel_frame, ros::Time(0));
      geometry_msgs::Pose pose;
      pose.position.x = tf.transform.translation.x;
      pose.position.y = tf.transform.translation.y;
      pose.position.z = tf.transform.translation.z;
      pose.orientation = tf.transform.rotation;
      std::string why;
      if (!is_finite_pose(pose))
        ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel tf pose: NaN/Inf");
      else if (!pose_input_.offer(to_blade_pose(pose, 0.0), &why))
        ROS_WARN_THROTTLE(1.0, "tissue_node: dropped scalpel tf pose: %s", why.c_str());
    } catch (const tf2::TransformException& e) {
      ROS_WARN_THROTTLE(5.0, "tissue_node: no transform %s -> %s: %s",
                        params_.scalpel_frame.c_str(), params_.frame_id.c_str(), e.what());
    }
  }
  return pose_input_.latest();
}

void TissueNode::loop() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / params_.rate));
  auto next = Clock::now();
  Clock::time_point previous{};
  double mean_dt = 1.0 / params_.rate;
  while (running_ && ros::ok()) {
    const Clock::time_point t0 = Clock::now();
    if (previous != Clock::time_point{}) {
      const double dt = std::chrono::duration<double>(t0 - previous).count();
      mean_dt += 0.05 * (dt - mean_dt);
    }
    previous = t0;
    const double rate = 1.0 / mean_dt;
    {
      std::lock_guard<std::mutex> lock(sim_mutex_);
      std::optional<BladePose> blade = current_blade();
      if (blade) blade->t = static_cast<double>(steps_) / params_.rate;
      const StepStats s = sim_->step(blade);
      if (s.reached_interface)
        ROS_WARN_THROTTLE(2.0, "the blade reached the interface of the condensed part: cutting "
                               "stops there (the cut stays inside the operation region)");
      if (!s.converged)
        ROS_WARN_THROTTLE(2.0, "CG did not converge this step (relative residual %.3g)",
                          s.residual);
      const ros::Time stamp = ros::Time::now();
      soft_tissue_cutting::SimStats stats =
          to_stats_msg(s, sim_->counts(), sim_->backend(), sim_->renderer(), rate);
      stats.header.stamp = stamp;
      stats.header.frame_id = params_.frame_id;
      stats_pub_.publish(stats);
      const bool blade_axes = params_.wrench_frame == "blade";
      geometry_msgs::WrenchStamped wrench = to_wrench_msg(s, blade_axes ? blade : std::nullopt);
      wrench.header = stats.header;
      if (blade_axes)
        wrench.header.frame_id = params_.scalpel_frame.empty() ? "scalpel" : params_.scalpel_frame;
      wrench_pub_.publish(wrench);

      // Display (<= display_rate): ~surface when the surface changed, ~markers (always every
      // namespace, so the latched message is complete) when the surface or the blade moved;
      // both at least once a second.
      const ros::WallTime now = ros::WallTime::now();
      const double min_gap = 1.0 / params_.display_rate;
      const bool changed = sim_->surface_version() != published_version_;
      const std::optional<BladePose> shown = pose_input_.latest();
      const bool blade_moved =
          shown.has_value() != shown_blade_.has_value() ||
          (shown && (shown->position != shown_blade_->position ||
                     !shown->orientation.coeffs().isApprox(shown_blade_->orientation.coeffs(), 0))) ||
          s.cutting != shown_cutting_;
      if ((changed && (now - last_surface_pub_).toSec() >= min_gap) ||
          (now - last_surface_pub_).toSec() >= 1.0)
        publish_surface_locked(stamp);
      else if (blade_moved && (now - last_markers_pub_).toSec() >= min_gap)
        publish_markers_locked(stamp);
      {
        std::lock_guard<std::mutex> slock(stats_mutex_);
        ++steps_;
        achieved_rate_ = rate;
        last_converged_ = s.converged;
      }
    }
    diagnostics_.update();
    next += period;
    const auto now = Clock::now();
    if (next < now - period) next = now;  // fell behind: do not try to catch up in a burst
    std::this_thread::sleep_until(next);
  }
}

void TissueNode::publish_surface_locked(const ros::Time& stamp) {
  const DeformedSurface s = sim_->surface();
  visualization_msgs::Marker m = surface_marker(s, SurfacePart::kAll);
  m.header.frame_id = params_.frame_id;
  m.header.stamp = stamp;
  published_version_ = sim_->surface_version();
  // The surface state's version travels as the header's sequence number (roscpp sends it as
  // set), not in `text`: rviz flags a TRIANGLE_LIST with text ("Non-empty text is ignored").
  m.header.seq = static_cast<std::uint32_t>(published_version_);
  m.action = visualization_msgs::Marker::ADD;
  surface_pub_.publish(m);
  last_surface_pub_ = ros::WallTime::now();

  std::string hash = sim_->mesh_hash();
  if (hash != last_hash_ || !published_any_) {
    std_msgs::String h;
    h.data = hash;
    hash_pub_.publish(h);
    last_hash_ = hash;
  }
  published_any_ = true;
  publish_markers_locked(stamp, &s);
}

void TissueNode::publish_markers_locked(const ros::Time& stamp, const DeformedSurface* surface) {
  visualization_msgs::MarkerArray array;
  const DeformedSurface s = surface ? *surface : sim_->surface();
  array.markers.push_back(surface_marker(s, SurfacePart::kSkin));
  array.markers.push_back(surface_marker(s, SurfacePart::kCut));
  for (auto& m : operation_region_markers(sim_->scene().operation_region).markers)
    array.markers.push_back(m);
  shown_blade_ = pose_input_.latest();
  shown_cutting_ = sim_->last_stats().cutting;
  for (auto& m : scalpel_markers(shown_blade_, sim_->scene().scalpel.blade_length, shown_cutting_)
                     .markers)
    array.markers.push_back(m);
  array.markers.push_back(contact_marker(sim_->last_stats().contact_points));
  for (auto& m : array.markers) {
    m.header.frame_id = params_.frame_id;
    m.header.stamp = stamp;
  }
  markers_pub_.publish(array);
  last_markers_pub_ = ros::WallTime::now();
}

bool TissueNode::on_cut(soft_tissue_cutting::Cut::Request& req,
                        soft_tissue_cutting::Cut::Response& res) {
  std::vector<BladePose> poses;
  for (size_t i = 0; i < req.poses.size(); ++i) {
    geometry_msgs::Pose pose;
    std::string why;
    if (!is_finite_pose(req.poses[i].pose)) {
      res.message = "pose " + std::to_string(i) + " is not finite";
      return true;
    }
    if (!to_scene_frame(req.poses[i], &pose, &why)) {
      res.message = "pose " + std::to_string(i) + ": " + why;
      return true;
    }
    poses.push_back(to_blade_pose(pose, static_cast<double>(i)));
  }
  if (poses.size() < 2) {
    res.message = "need at least two poses to sweep a cut";
    return true;
  }
  std::lock_guard<std::mutex> lock(sim_mutex_);
  try {
    const CutOutcome out = sim_->cut_along(poses);
    res.success = out.success;
    res.message = out.message;
    res.tets_split = static_cast<uint32_t>(std::max(0, out.tets_split));
    res.nodes_added = static_cast<uint32_t>(std::max(0, out.nodes_added));
    res.cut_faces = static_cast<uint32_t>(std::max(0, out.cut_faces));
  } catch (const std::exception& e) {
    res.success = false;
    res.message = std::string("cut failed: ") + e.what();
  }
  publish_surface_locked(ros::Time::now());
  return true;
}

bool TissueNode::on_reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lock(sim_mutex_);
  try {
    sim_->reset();
    pose_input_.clear();
    publish_surface_locked(ros::Time::now());
    res.success = true;
    res.message = "reset to the initial state (surface_version " +
                  std::to_string(published_version_) + ")";
  } catch (const std::exception& e) {
    res.success = false;
    res.message = std::string("reset failed: ") + e.what();
  }
  return true;
}

bool TissueNode::on_set_cutting(std_srvs::SetBool::Request& req,
                                std_srvs::SetBool::Response& res) {
  {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    sim_->set_cutting_enabled(req.data);
  }
  {
    boost::recursive_mutex::scoped_lock lock(reconfigure_mutex_);
    config_.cutting_enabled = req.data;
  }
  reconfigure_->updateConfig(config_);  // keep dynamic_reconfigure in step
  res.success = true;
  res.message = req.data ? "pressure-triggered cutting enabled"
                         : "pressure-triggered cutting disabled";
  return true;
}

bool TissueNode::on_save(soft_tissue_cutting::SaveMesh::Request& req,
                         soft_tissue_cutting::SaveMesh::Response& res) {
  if (req.path.empty()) {
    res.message = "path is empty";
    return true;
  }
  std::lock_guard<std::mutex> lock(sim_mutex_);
  try {
    sim_->write_vtk(req.path);
    if (!req.stats_path.empty()) {
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started_)
              .count();
      sim_->write_stats_json(req.stats_path, ms);
    }
    res.success = true;
    res.message = "wrote " + req.path + (req.stats_path.empty() ? "" : " and " + req.stats_path);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

void TissueNode::on_reconfigure(soft_tissue_cutting::TissueConfig& config, uint32_t) {
  std::lock_guard<std::mutex> lock(sim_mutex_);
  try {
    sim_->set_cut_pressure(config.cut_pressure);
    sim_->set_young_modulus(config.young_modulus);
    sim_->set_cutting_enabled(config.cutting_enabled);
    config_ = config;
  } catch (const std::exception& e) {
    ROS_ERROR("tissue_node: reconfigure refused: %s", e.what());
  }
}

void TissueNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  double rate;
  bool converged;
  std::uint64_t steps;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    rate = achieved_rate_;
    converged = last_converged_;
    steps = steps_;
  }
  const bool rate_kept = rate >= 0.9 * params_.rate;
  const std::string backend = sim_->backend();  // const, set at construction
  if (!converged)
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "solver did not converge");
  else if (!rate_kept)
    status.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "rate not kept: %.1f of %.1f Hz",
                    rate, params_.rate);
  else
    status.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "running at %.1f Hz on %s", rate,
                    backend.c_str());
  status.add("rate target (Hz)", params_.rate);
  status.add("rate achieved (Hz)", rate);
  status.add("rate kept", rate_kept);
  status.add("solver converged", converged);
  status.add("backend", backend);
  status.add("renderer", sim_->renderer());
  status.add("backend note", sim_->backend_note());
  status.add("steps", steps);
}

}  // namespace ros_io
}  // namespace stc
