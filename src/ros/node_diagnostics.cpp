// /diagnostics from its own thread: LoopMonitor::report (worst step and rate over the last
// second, widened to everything since the previous publish: any non-converged solve, slow step
// or stall in between is reported once) plus the backend in use. It never takes the simulation
// lock, so it keeps publishing while the simulation is busy, and a stalled loop shows up as an
// ERROR.
#include "soft_tissue_cutting/ros/heap_release.hpp"
#include "soft_tissue_cutting/ros/tissue_node.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace stc {
namespace ros_io {

void TissueNode::diagnostics_thread() {
  auto next_release = std::chrono::steady_clock::now();
  while (running_ && ros::ok()) {
    diagnostics_.update();  // publishes once per its period (1 s)
    // What cuts free inside the heaps goes back to the system every 10 s, off the loop.
    if (std::chrono::steady_clock::now() >= next_release) {
      release_free_heap();
      next_release = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

void TissueNode::remember_backend_locked() {
  std::lock_guard<std::mutex> lock(info_mutex_);
  backend_ = sim_->backend();
  renderer_ = sim_->renderer();
  backend_note_ = sim_->backend_note();
  // What the simulation itself uses (after ~reset too), not what the server was told.
  const Scene& scene = sim_->scene();
  tuning_ = {scene.scalpel.cut_pressure, scene.material.young_modulus,
             scene.scalpel.shape_guard_deg};
}

void TissueNode::remember_solver_failure(const std::string& why) {
  std::lock_guard<std::mutex> lock(info_mutex_);
  solver_failure_ = why;
}

void TissueNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const LoopHealth h = monitor_.report(LoopMonitor::Clock::now());
  std::string backend, renderer, note, failure, solved_by, fallback;
  std::optional<RegionMoveStats> moves;
  int sweeps_waiting = 0;
  double cut_lag = 0;
  Tuning tuning;
  {
    std::lock_guard<std::mutex> lock(info_mutex_);
    backend = backend_;
    renderer = renderer_;
    note = backend_note_;
    failure = solver_failure_;
    solved_by = solved_by_;
    fallback = fallback_reason_;
    moves = region_moves_;
    sweeps_waiting = sweeps_waiting_;
    cut_lag = cut_lag_;
    tuning = tuning_;
  }
  const double period_ms = 1000.0 / params_.rate;
  std::string summary = h.level == LoopHealth::kOk ? h.summary + " on " + backend : h.summary;
  if (!h.stalled && !h.converged && !failure.empty()) summary += ": " + failure;
  status.summary(h.level, summary);
  status.add("rate target (Hz)", params_.rate);
  status.add("rate achieved (Hz)", h.rate_hz);  // steps in the last second
  status.add("rate kept", h.rate_hz >= 0.9 * params_.rate);
  status.add("worst step last second (ms)", h.worst_step_ms);
  status.add("worst step since start (ms)", h.worst_step_ms_ever);
  status.add("period (ms)", period_ms);
  status.add("steps over the period", h.slow_steps);
  status.add("since last step (s)", h.since_last_step_s);
  status.add("step in progress for (s)", h.busy_step_s);
  status.add("longest gap since last report (s)", h.longest_gap_s);
  status.add("stalled", h.stalled);             // now, or at any time since the last report
  status.add("solver converged", h.converged);  // every solve since the last report
  status.add("non-converged solves since last report", h.unconverged_steps);
  status.add("backend", backend);
  status.add("renderer", renderer);
  status.add("backend note", note);
  status.add("solved by", solved_by);  // cpu when a gl solve fell back
  status.add("fallback reason", fallback);
  status.add("steps", h.steps);
  // The live tuning in use (dynamic_reconfigure's values, kept through ~reset).
  status.add("cut pressure (N)", tuning.cut_pressure);
  status.add("Young's modulus (Pa)", tuning.young_modulus);
  status.add("shape guard (deg)", tuning.shape_guard_deg);
  if (moves) {  // `follow` operation region (docs/ROS.md "API")
    std::vector<double> d = moves->durations_ms;
    std::sort(d.begin(), d.end());
    status.add("region moves", moves->moves);
    status.add("region moves failed", moves->failed);
    status.add("region moving", moves->moving);
    status.add("region move last (ms)", moves->last_ms);
    status.add("region move median (ms)", d.empty() ? 0.0 : d[d.size() / 2]);
    status.add("region move max (ms)", moves->max_ms);
    status.add("region move wait (ms)", moves->last_wait_ms);
    char centre[96];
    std::snprintf(centre, sizeof centre, "%.4f %.4f %.4f", moves->ball.center.x(),
                  moves->ball.center.y(), moves->ball.center.z());
    status.add("region centre (m)", std::string(centre));
    status.add("region move reason", moves->last_reason);
    // How far the cut trails the blade (waiting for a move, or cut a few ms a step after one).
    status.add("sweeps waiting", sweeps_waiting);
    status.add("cut lag (m)", cut_lag);
  }
}

}  // namespace ros_io
}  // namespace stc
