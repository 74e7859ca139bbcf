#include "soft_tissue_cutting/ros/loop_monitor.hpp"

#include <algorithm>
#include <cstdio>

namespace stc {
namespace ros_io {

namespace {
double seconds(LoopMonitor::Clock::duration d) { return std::chrono::duration<double>(d).count(); }
}  // namespace

LoopMonitor::LoopMonitor(double target_rate, Clock::time_point started, double stall_after_s)
    : target_rate_(target_rate),
      period_ms_(1000.0 / target_rate),
      stall_after_s_(std::max(stall_after_s, 10.0 / target_rate)),
      started_(started),
      last_finished_(started) {}

void LoopMonitor::step_started(Clock::time_point t) {
  std::lock_guard<std::mutex> lock(mutex_);
  in_progress_ = true;
  in_progress_since_ = t;
}

void LoopMonitor::step_finished(Clock::time_point t, bool converged) {
  std::lock_guard<std::mutex> lock(mutex_);
  const Clock::time_point start = in_progress_ ? in_progress_since_ : t;
  const double ms = 1000.0 * seconds(t - start);
  in_progress_ = false;
  last_finished_ = t;
  ++steps_;
  if (ms > period_ms_) ++slow_steps_;
  worst_ever_ms_ = std::max(worst_ever_ms_, ms);
  converged_ = converged;
  window_.push_back({start, ms});
  prune_locked(t);
}

void LoopMonitor::prune_locked(Clock::time_point now) const {
  while (!window_.empty() && seconds(now - window_.front().start) > 1.0) window_.pop_front();
}

LoopHealth LoopMonitor::health(Clock::time_point now) const {
  std::lock_guard<std::mutex> lock(mutex_);
  prune_locked(now);
  LoopHealth h;
  h.steps = steps_;
  h.slow_steps = slow_steps_;
  h.converged = converged_;
  h.worst_step_ms_ever = worst_ever_ms_;
  for (const Step& s : window_) h.worst_step_ms = std::max(h.worst_step_ms, s.ms);
  if (in_progress_) {
    h.busy_step_s = seconds(now - in_progress_since_);
    // A step still running longer than the period is already a slow step.
    h.worst_step_ms = std::max(h.worst_step_ms, 1000.0 * h.busy_step_s);
  }
  const double age = std::max(1e-9, seconds(now - started_));
  h.rate_hz = static_cast<double>(window_.size()) / std::min(1.0, age);
  h.since_last_step_s = seconds(now - last_finished_);
  h.stalled = h.since_last_step_s > stall_after_s_;

  char buf[200];
  if (h.stalled) {
    h.level = LoopHealth::kError;
    std::snprintf(buf, sizeof buf, "loop stalled: no step finished for %.2f s",
                  h.since_last_step_s);
  } else if (!h.converged) {
    h.level = LoopHealth::kError;
    std::snprintf(buf, sizeof buf, "solver did not converge");
  } else if (h.worst_step_ms > period_ms_ || h.rate_hz < 0.9 * target_rate_) {
    h.level = LoopHealth::kWarn;
    std::snprintf(buf, sizeof buf,
                  "rate not kept: %.1f of %.1f Hz, worst step %.1f ms (period %.1f ms)", h.rate_hz,
                  target_rate_, h.worst_step_ms, period_ms_);
  } else {
    h.level = LoopHealth::kOk;
    std::snprintf(buf, sizeof buf, "running at %.1f Hz, worst step %.1f ms", h.rate_hz,
                  h.worst_step_ms);
  }
  h.summary = buf;
  return h;
}

}  // namespace ros_io
}  // namespace stc
