// How much the drawn surface costs the simulation loop (docs/ROS.md (threads)), without ROS:
// a loop thread steps SCENE at 100 Hz under a lock, the blade pressing in and out (cutting
// off, so every step solves and u_I moves), while the surface is refreshed at 30 Hz either
//   inloop:  by the loop itself, Simulation::surface() under the lock (tissue_node before the
//            display thread: u_S recovered inside the loop iteration), or
//   display: by a display thread, surface_snapshot() under the lock (copies only) and
//            SurfaceSnapshot::compute() outside it, its recovery handed back at the next
//            refresh (tissue_node's display thread).
// Prints, per mode, the loop iteration time with the lock held (step + what the loop does for
// the display), the time the loop waited for the lock, the refresh rate and the surface
// computation time (the recovery of u_S when stale).
// Usage: tissue_display_timing SCENE.yaml [seconds per mode (10)] [rounds (2)]
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

std::string summary(std::vector<double> v) {
  if (v.empty()) return "none";
  std::sort(v.begin(), v.end());
  auto at = [&](double q) { return v[std::min(v.size() - 1, static_cast<size_t>(q * v.size()))]; };
  char buf[160];
  std::snprintf(buf, sizeof buf, "median %6.2f  p90 %6.2f  p99 %6.2f  max %7.2f ms (n=%zu)",
                at(0.5), at(0.9), at(0.99), v.back(), v.size());
  return buf;
}

// The blade at step k: the scene's first pressing pose, moved 0..8 mm along the press
// direction and back over 2 s.
stc::BladePose pose_at(const stc::Scene& scene, long k) {
  const stc::BladePose& above = scene.trajectory.at(0);
  const stc::BladePose& in = scene.trajectory.at(1);
  const double depth = 0.5 * (1 - std::cos(2 * M_PI * static_cast<double>(k) / 200.0));
  stc::BladePose p = in;
  const stc::Vec3 dir = (in.position - above.position).normalized();
  p.position = above.position + dir * (0.008 * depth + 0.5 * (in.position - above.position).norm());
  return p;
}

void run(const stc::Scene& scene, bool display_thread, double seconds) {
  stc::Simulation sim(scene);
  sim.set_cutting_enabled(false);
  std::mutex lock;
  std::atomic<bool> running{true};
  std::vector<double> held, waited, steps, refresh, compute;
  long refreshes = 0, solved = 0;
  const auto period = std::chrono::milliseconds(10), display_period = std::chrono::milliseconds(33);

  std::thread display;
  if (display_thread)
    display = std::thread([&] {
      std::optional<stc::SurfaceSnapshot> recovered;
      while (running) {
        const auto t0 = Clock::now();
        stc::SurfaceSnapshot s;
        {
          std::lock_guard<std::mutex> g(lock);
          const auto t1 = Clock::now();
          if (recovered) sim.adopt_recovery(*recovered);
          s = sim.surface_snapshot();
          refresh.push_back(ms(Clock::now() - t1));  // display's lock hold
        }
        recovered.reset();
        const bool stale = s.displacement.stale;
        const auto t2 = Clock::now();
        const stc::DeformedSurface d = s.compute();
        compute.push_back(ms(Clock::now() - t2));
        if (d.positions.empty()) std::abort();
        if (stale) recovered = std::move(s);
        ++refreshes;
        std::this_thread::sleep_until(t0 + display_period);
      }
    });

  const auto start = Clock::now();
  auto next = start, next_surface = start;
  long k = 0;
  while (Clock::now() - start < std::chrono::duration<double>(seconds)) {
    const auto t0 = Clock::now();
    {
      std::lock_guard<std::mutex> g(lock);
      const auto t1 = Clock::now();
      waited.push_back(ms(t1 - t0));
      const stc::StepStats st = sim.step(pose_at(scene, k++));
      steps.push_back(st.step_ms);
      solved += st.cg_iterations > 0;
      if (!display_thread && t1 >= next_surface) {
        const auto t2 = Clock::now();
        const stc::DeformedSurface d = sim.surface();
        compute.push_back(ms(Clock::now() - t2));
        if (d.positions.empty()) std::abort();
        ++refreshes;
        next_surface = t1 + display_period;
      }
      held.push_back(ms(Clock::now() - t1));
    }
    next += period;
    if (next < Clock::now() - period) next = Clock::now();
    std::this_thread::sleep_until(next);
  }
  running = false;
  if (display.joinable()) display.join();
  const double wall = ms(Clock::now() - start) / 1000;
  std::printf("%s: %ld steps (%.1f /s, %ld solved), %ld surface refreshes (%.1f /s)\n",
              display_thread ? "display" : "inloop ", k, k / wall, solved, refreshes,
              refreshes / wall);
  std::printf("  loop iteration, lock held:  %s\n", summary(held).c_str());
  std::printf("  step_ms (Simulation::step): %s\n", summary(steps).c_str());
  std::printf("  loop waited for the lock:   %s\n", summary(waited).c_str());
  std::printf("  surface computation:        %s\n", summary(compute).c_str());
  if (display_thread) std::printf("  display's lock hold:        %s\n", summary(refresh).c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  stc::reexec_with_native_blas_kernels(argv);  // before anything runs (blas_kernels.hpp)
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE.yaml [seconds per mode] [rounds]\n", argv[0]);
    return 2;
  }
  const stc::Scene scene = stc::load_scene(argv[1]);
  const double seconds = argc > 2 ? std::stod(argv[2]) : 10;
  const int rounds = argc > 3 ? std::stoi(argv[3]) : 2;
  for (int r = 0; r < rounds; ++r) {
    run(scene, false, seconds);
    run(scene, true, seconds);
  }
  return 0;
}
