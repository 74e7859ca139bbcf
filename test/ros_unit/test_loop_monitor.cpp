// LoopMonitor with injected times: rate and worst step over the last second, WARN when a step
// exceeds the period, ERROR when the loop stalls or the solve did not converge.
#include "soft_tissue_cutting/ros/loop_monitor.hpp"

#include <gtest/gtest.h>

namespace stc::ros_io {
namespace {

using Clock = LoopMonitor::Clock;
using ms = std::chrono::duration<double, std::milli>;

Clock::time_point t(double milliseconds) {
  return Clock::time_point{} + std::chrono::hours(1) +
         std::chrono::duration_cast<Clock::duration>(ms(milliseconds));
}

// `n` steps of `step_ms` every `period_ms` from `start_ms`; returns the end time.
double run(LoopMonitor& m, double start_ms, int n, double period_ms, double step_ms,
           bool converged = true) {
  for (int i = 0; i < n; ++i) {
    m.step_started(t(start_ms + i * period_ms));
    m.step_finished(t(start_ms + i * period_ms + step_ms), converged);
  }
  return start_ms + n * period_ms;
}

TEST(LoopMonitor, KeptRateIsOk) {
  LoopMonitor m(100, t(0));
  const double end = run(m, 0, 300, 10, 4);
  const LoopHealth h = m.health(t(end));
  EXPECT_EQ(h.level, LoopHealth::kOk) << h.summary;
  EXPECT_NEAR(h.rate_hz, 100, 1);
  EXPECT_NEAR(h.worst_step_ms, 4, 1e-6);
  EXPECT_EQ(h.steps, 300u);
  EXPECT_EQ(h.slow_steps, 0u);
}

TEST(LoopMonitor, OneSlowStepWarnsForOneSecond) {
  LoopMonitor m(100, t(0));
  double end = run(m, 0, 100, 10, 4);
  m.step_started(t(end));
  m.step_finished(t(end + 35), true);  // 35 ms > 10 ms period
  end = run(m, end + 40, 20, 10, 4);
  LoopHealth h = m.health(t(end));
  EXPECT_EQ(h.level, LoopHealth::kWarn) << h.summary;
  EXPECT_NEAR(h.worst_step_ms, 35, 1e-6);
  EXPECT_EQ(h.slow_steps, 1u);
  EXPECT_NE(h.summary.find("worst step 35.0 ms"), std::string::npos) << h.summary;
  end = run(m, end, 150, 10, 4);  // the slow step leaves the window
  h = m.health(t(end));
  EXPECT_EQ(h.level, LoopHealth::kOk) << h.summary;
  EXPECT_NEAR(h.worst_step_ms_ever, 35, 1e-6);
}

TEST(LoopMonitor, LowRateWarns) {
  LoopMonitor m(100, t(0));
  const double end = run(m, 0, 200, 14, 4);  // 71 Hz, every step within the period
  const LoopHealth h = m.health(t(end));
  EXPECT_EQ(h.level, LoopHealth::kWarn) << h.summary;
  EXPECT_NEAR(h.rate_hz, 1000.0 / 14, 1.5);
}

TEST(LoopMonitor, AStepThatNeverEndsIsAStall) {
  LoopMonitor m(100, t(0));
  const double end = run(m, 0, 100, 10, 4);
  m.step_started(t(end));
  LoopHealth h = m.health(t(end + 500));  // busy 0.5 s: slow, not yet stalled
  EXPECT_EQ(h.level, LoopHealth::kWarn) << h.summary;
  EXPECT_NEAR(h.busy_step_s, 0.5, 1e-6);
  h = m.health(t(end + 2500));
  EXPECT_EQ(h.level, LoopHealth::kError) << h.summary;
  EXPECT_TRUE(h.stalled);
  EXPECT_EQ(h.rate_hz, 0.0);
  EXPECT_NE(h.summary.find("loop stalled"), std::string::npos) << h.summary;
}

TEST(LoopMonitor, NotConvergedIsAnError) {
  LoopMonitor m(100, t(0));
  const double end = run(m, 0, 50, 10, 4, false);
  const LoopHealth h = m.health(t(end));
  EXPECT_EQ(h.level, LoopHealth::kError);
  EXPECT_FALSE(h.converged);
  EXPECT_EQ(h.summary, "solver did not converge");
}

TEST(LoopMonitor, YoungMonitorRatesOverItsAge) {
  LoopMonitor m(100, t(0));
  const double end = run(m, 0, 50, 10, 4);  // 0.5 s old
  EXPECT_NEAR(m.health(t(end)).rate_hz, 100, 2);
}

}  // namespace
}  // namespace stc::ros_io
