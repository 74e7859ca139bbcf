// Health of the simulation loop for /diagnostics: every step is measured (start, duration,
// converged), and the report covers the last second: achieved rate, worst step, and whether
// the loop stalled. Thread-safe: the loop records, the diagnostics thread reports, and neither
// takes the simulation lock, so a busy simulation is still reported (as stalled).
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>

namespace stc {
namespace ros_io {

struct LoopHealth {
  enum Level : std::uint8_t { kOk = 0, kWarn = 1, kError = 2 };  // diagnostic_msgs levels
  Level level = kOk;
  std::string summary;
  double rate_hz = 0;             // steps started in the last second (over the age if younger)
  double worst_step_ms = 0;       // longest step finished in the last second
  double worst_step_ms_ever = 0;  // longest step since start
  double since_last_step_s = 0;   // since the last step finished (or the monitor started)
  double busy_step_s = 0;         // how long the step in progress has run (0 if none)
  std::uint64_t steps = 0;
  std::uint64_t slow_steps = 0;  // steps longer than the period, since start
  bool converged = true;         // the last step's solve
  bool stalled = false;
};

class LoopMonitor {
 public:
  using Clock = std::chrono::steady_clock;
  // target_rate: ~rate (steps/s). A loop with no finished step for stall_after_s (at least
  // ten periods) is stalled.
  LoopMonitor(double target_rate, Clock::time_point started, double stall_after_s = 1.0);

  void step_started(Clock::time_point t);
  void step_finished(Clock::time_point t, bool converged);
  LoopHealth health(Clock::time_point now) const;
  double target_rate() const { return target_rate_; }

 private:
  struct Step {
    Clock::time_point start;
    double ms;
  };
  void prune_locked(Clock::time_point now) const;

  mutable std::mutex mutex_;
  const double target_rate_;
  const double period_ms_;
  const double stall_after_s_;
  const Clock::time_point started_;
  mutable std::deque<Step> window_;  // steps started in the last second
  Clock::time_point last_finished_;
  Clock::time_point in_progress_since_;
  bool in_progress_ = false;
  std::uint64_t steps_ = 0, slow_steps_ = 0;
  double worst_ever_ms_ = 0;
  bool converged_ = true;
};

}  // namespace ros_io
}  // namespace stc
