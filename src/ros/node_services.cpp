// The node's services and dynamic_reconfigure. None holds the simulation lock for longer than
// about one step: ~cut hands its path to the loop (inserted in slices between steps) and
// waits; ~reset builds the fresh Simulation outside the lock and swaps it in; ~save copies
// the state under the lock and writes the files outside it.
#include "soft_tissue_cutting/cutting/blade_path.hpp"
#include "soft_tissue_cutting/io/vtk_writer.hpp"
#include "soft_tissue_cutting/ros/conversions.hpp"
#include "soft_tissue_cutting/ros/heap_release.hpp"
#include "soft_tissue_cutting/ros/log_text.hpp"
#include "soft_tissue_cutting/ros/tissue_node.hpp"

#include <cstdio>
#include <fstream>

namespace stc {
namespace ros_io {

namespace {
// ~cut calls wait on spinner threads (tissue_node_main.cpp has 6): at most 3 wait, so poses
// and the other services always find a free thread.
constexpr int kMaxWaitingCuts = 3;

// Writes `text` to `path`; false (and *why) on failure.
bool write_text(const std::string& path, const std::string& text, std::string* why) {
  std::ofstream out(path);
  if (out) out << text << "\n";
  out.close();
  if (!out) *why = shorten(path) + ": cannot write";
  return static_cast<bool>(out);
}
}  // namespace

bool TissueNode::on_cut(soft_tissue_cutting::Cut::Request& req,
                        soft_tissue_cutting::Cut::Response& res) {
  if (req.poses.size() > static_cast<size_t>(params_.max_cut_poses)) {
    res.message = "refused: " + std::to_string(req.poses.size()) +
                  " poses exceed ~max_cut_poses = " + std::to_string(params_.max_cut_poses);
    return true;
  }
  auto job = std::make_shared<CutJob>();
  job->poses.reserve(req.poses.size());
  for (size_t i = 0; i < req.poses.size(); ++i) {
    geometry_msgs::Pose pose;
    std::string why = pose_problem(req.poses[i].pose);
    if (why.empty()) to_scene_frame(req.poses[i], &pose, &why);
    if (!why.empty()) {
      res.message = "pose " + std::to_string(i) + ": " + why;
      return true;
    }
    job->poses.push_back(to_blade_pose(pose, static_cast<double>(i)));
  }
  if (job->poses.size() < 2) {
    res.message = "need at least two poses to sweep a cut";
    return true;
  }
  const double length = blade_path_length(job->poses, initial_scene_.scalpel.blade_length);
  if (length > params_.max_cut_length) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "refused: the blade travels %.4g m along the path, more than ~max_cut_length = "
                  "%.4g m",
                  length, params_.max_cut_length);
    res.message = buf;
    return true;
  }
  std::unique_lock<std::mutex> lock(cut_mutex_);
  if (cuts_waiting_ >= kMaxWaitingCuts) {
    res.message = "refused: " + std::to_string(cuts_waiting_) +
                  " cuts are already waiting; try again when they are done";
    return true;
  }
  queued_cuts_.push_back(job);
  ++cuts_waiting_;
  // The loop inserts the path a slice per step and answers; a stopping node answers too.
  cut_done_.wait(lock, [&] { return job->finished; });
  --cuts_waiting_;
  const CutOutcome& out = job->outcome;
  res.success = out.success;
  res.message = out.message;
  res.tets_split = static_cast<uint32_t>(std::max(0, out.tets_split));
  res.nodes_added = static_cast<uint32_t>(std::max(0, out.nodes_added));
  res.cut_faces = static_cast<uint32_t>(std::max(0, out.cut_faces));
  return true;
}

bool TissueNode::on_reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::unique_ptr<Simulation> fresh;
  try {
    fresh = std::make_unique<Simulation>(initial_scene_, options_);  // outside the lock
    // The live tuning survives a reset (dynamic_reconfigure still shows it): before, a reset
    // went back to the scene's cut pressure, E and shape guard while the server kept the
    // tuned values. (~set_cutting's flag is taken from the running simulation below.)
    soft_tissue_cutting::TissueConfig tuned;
    {
      boost::recursive_mutex::scoped_lock lock(reconfigure_mutex_);
      tuned = config_;
    }
    apply_tuning(*fresh, tuned);
  } catch (const std::exception& e) {
    res.success = false;
    res.message = "reset failed: " + shorten(e.what());
    return true;
  }
  std::deque<std::shared_ptr<CutJob>> cancelled;
  std::optional<DisplayFrame> frame;
  {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    fresh->set_cutting_enabled(sim_->cutting_enabled());  // ~set_cutting survives a reset
    std::swap(sim_, fresh);
    ++sim_generation_;
    pose_input_.clear();
    if (active_cut_) cancelled.push_back(active_cut_);
    active_cut_.reset();
    {
      std::lock_guard<std::mutex> qlock(cut_mutex_);
      for (auto& job : queued_cuts_) cancelled.push_back(job);
      queued_cuts_.clear();
    }
    remember_backend_locked();
    frame = display_frame_locked(true);  // the fresh state, drawn outside the lock
  }
  publish_frame(std::move(*frame));
  answer_cuts(std::move(cancelled), "cancelled by ~reset");
  fresh.reset();  // the old state is freed outside the lock
  release_free_heap();
  res.success = true;
  res.message = "reset to the initial state";
  return true;
}

bool TissueNode::on_set_cutting(std_srvs::SetBool::Request& req, std_srvs::SetBool::Response& res) {
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
  res.message =
      req.data ? "pressure-triggered cutting enabled" : "pressure-triggered cutting disabled";
  return true;
}

bool TissueNode::on_save(soft_tissue_cutting::SaveMesh::Request& req,
                         soft_tissue_cutting::SaveMesh::Response& res) {
  if (req.path.empty()) {
    res.message = "path is empty";
    return true;
  }
  // Copy the state under the lock, write outside it.
  TetMesh mesh;
  Eigen::VectorXd u;
  std::vector<std::uint8_t> regions;
  std::string json;
  try {
    std::lock_guard<std::mutex> lock(sim_mutex_);
    u = sim_->full_displacement();
    mesh = sim_->mesh();
    regions = sim_->tet_regions();
    if (!req.stats_path.empty()) {
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started_)
              .count();
      json = sim_->stats_json(ms);
    }
  } catch (const std::exception& e) {
    res.message = "save failed: " + shorten(e.what());
    return true;
  }
  // Both files are written beside their targets and renamed only when both were written, so
  // success means everything was written and a failure leaves no partial output.
  const std::string vtk_tmp = req.path + ".part", json_tmp = req.stats_path + ".part";
  std::string why;
  try {
    write_vtk(vtk_tmp, mesh, u, regions);
  } catch (const std::exception& e) {
    why = shorten(e.what());
  }
  if (why.empty() && !req.stats_path.empty()) write_text(json_tmp, json, &why);
  if (why.empty() && std::rename(vtk_tmp.c_str(), req.path.c_str()) != 0)
    why = shorten(req.path) + ": cannot rename the written file into place";
  if (why.empty() && !req.stats_path.empty() &&
      std::rename(json_tmp.c_str(), req.stats_path.c_str()) != 0)
    why = shorten(req.stats_path) + ": cannot rename the written file into place";
  std::remove(vtk_tmp.c_str());
  if (!req.stats_path.empty()) std::remove(json_tmp.c_str());
  res.success = why.empty();
  res.message = why.empty() ? "wrote " + shorten(req.path) +
                                  (req.stats_path.empty() ? "" : " and " + shorten(req.stats_path))
                            : "nothing saved: " + why;
  return true;
}

void TissueNode::on_reconfigure(soft_tissue_cutting::TissueConfig& config, uint32_t) {
  std::lock_guard<std::mutex> lock(sim_mutex_);
  try {
    apply_tuning(*sim_, config);
    config_ = config;
    remember_backend_locked();  // and the tuning now in use
  } catch (const std::exception& e) {
    ROS_ERROR("tissue_node: reconfigure refused: %s", e.what());
  }
}

void TissueNode::apply_tuning(Simulation& sim, const soft_tissue_cutting::TissueConfig& config) {
  sim.set_cut_pressure(config.cut_pressure);
  // Only a change rescales the model (a reset's fresh one stays bit for bit the scene's).
  if (config.young_modulus != sim.scene().material.young_modulus)
    sim.set_young_modulus(config.young_modulus);
  sim.set_cutting_enabled(config.cutting_enabled);
  sim.set_shape_guard_deg(config.shape_guard_deg);
}

}  // namespace ros_io
}  // namespace stc
