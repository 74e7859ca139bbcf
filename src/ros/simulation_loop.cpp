// The simulation loop: one step per period at ~rate, every step measured (LoopMonitor), and
// the ~cut path in progress inserted in bounded slices between steps, so a long cut never
// stops the loop or its publishing. The surface is drawn by the display thread
// (node_display.cpp), never here.
#include "soft_tissue_cutting/ros/tissue_node.hpp"

namespace stc {
namespace ros_io {

void TissueNode::loop() {
  using Clock = LoopMonitor::Clock;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / params_.rate));
  auto next = Clock::now();
  while (running_ && ros::ok()) {
    const Clock::time_point t0 = Clock::now();
    monitor_.step_started(t0);
    bool converged = true;
    std::string failure;
    {
      std::lock_guard<std::mutex> lock(sim_mutex_);
      // A ~cut slice first (up to ~40 % of the period, at least one sweep; see
      // advance_cut_locked), then the step that solves on the cut mesh.
      advance_cut_locked(t0 + period * 2 / 5);
      std::int64_t scalpel_stamp_ns = 0;
      std::optional<BladePose> blade = current_blade(&scalpel_stamp_ns);
      if (const std::uint64_t dropped = pose_input_.dropped(); dropped != poses_dropped_seen_) {
        ROS_WARN_THROTTLE(2.0,
                          "~every_pose: %llu scalpel poses dropped so far (more than %zu waited: "
                          "they arrive faster than ~rate steps them)",
                          static_cast<unsigned long long>(dropped), kEveryPoseQueue);
        poses_dropped_seen_ = dropped;
      }
      if (blade) blade->t = static_cast<double>(steps_) / params_.rate;
      const StepStats s = sim_->step(blade);
      converged = s.converged;
      failure = s.solver_message;
      if (s.reached_interface && s.region_moving)
        ROS_WARN_THROTTLE(2.0,
                          "the cut waits at the interface while the operation region moves "
                          "to the blade");
      else if (s.reached_interface)
        ROS_WARN_THROTTLE(2.0,
                          "the blade reached the interface of the condensed part: cutting "
                          "stops there (the cut stays inside the operation region)");
      if (!s.converged)
        ROS_ERROR_THROTTLE(2.0, "the solve did not converge this step: %s",
                           s.solver_message.c_str());
      if (!s.fallback_reason.empty()) ROS_WARN_THROTTLE(10.0, "%s", s.fallback_reason.c_str());
      finish_cut_locked(s);
      const ros::Time stamp = ros::Time::now();
      publish_step_locked(s, blade, scalpel_stamp_ns, stamp, monitor_.health(Clock::now()).rate_hz);
      ++steps_;
    }
    monitor_.step_finished(Clock::now(), converged);
    if (!converged) remember_solver_failure(failure);
    next += period;
    const auto now = Clock::now();
    if (next < now - period) next = now;  // fell behind: do not try to catch up in a burst
    std::this_thread::sleep_until(next);
  }
}

void TissueNode::advance_cut_locked(LoopMonitor::Clock::time_point deadline) {
  if (!active_cut_) {
    std::lock_guard<std::mutex> lock(cut_mutex_);
    if (queued_cuts_.empty()) return;
    active_cut_ = queued_cuts_.front();
    queued_cuts_.pop_front();
  }
  CutJob& job = *active_cut_;
  if (!job.begun) {
    job.path = sim_->begin_path_cut(job.poses);
    job.begun = true;
    job.poses.clear();
    job.poses.shrink_to_fit();
  }
  if (job.path.done()) return;
  // One sweep cannot be split (tens of ms on the thigh), so slices are also spaced out: after
  // a slice of d, the loop steps without cutting for 1.5 d, so the cut takes at most ~40 % of
  // the loop's time and the steps in between keep their rate.
  const auto now = LoopMonitor::Clock::now();
  if (now < next_cut_slice_) return;
  sim_->cut_path_slice(job.path, deadline);
  const auto end = LoopMonitor::Clock::now();
  next_cut_slice_ = end + (end - now) * 3 / 2;
}

void TissueNode::finish_cut_locked(const StepStats& step) {
  if (!active_cut_ || !active_cut_->path.done()) return;
  CutOutcome out = sim_->finish_path_cut(active_cut_->path);
  if (out.success && !step.converged) out.message += "; warning: the solver did not converge";
  active_cut_->outcome = out;
  std::deque<std::shared_ptr<CutJob>> done{active_cut_};
  active_cut_.reset();
  answer_cuts(std::move(done), "");
}

void TissueNode::answer_cuts(std::deque<std::shared_ptr<CutJob>> jobs, const std::string& why) {
  if (jobs.empty()) return;
  {
    std::lock_guard<std::mutex> lock(cut_mutex_);
    for (auto& job : jobs) {
      if (!why.empty()) {
        job->outcome = CutOutcome{};
        job->outcome.message = "cut not done: " + why;
      }
      job->finished = true;
    }
  }
  cut_done_.notify_all();
}

}  // namespace ros_io
}  // namespace stc
