// The operation region that follows the scalpel (simulation/region_follower.hpp): how long a
// move takes (re-partition + re-condensation of part 2 + hybrid assembly and factorization, as
// the worker thread runs it) at paper scale (the built-in thigh) and on the organ-scale liver
// of config/scenes/liver_organ.yaml (its 2 cm sphere made a `follow` ball); the same model built
// from scratch (element matrices recomputed) for the gain of re-using them; the per-step solve
// while a move runs on the other core; and a whole stroke played online at 100 Hz.
#include "simulation/region_follower.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/partition/follow_region.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/region_move_stats.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

namespace stc {
namespace {

struct FollowCase {
  Scene scene;               // region: a ball at `from`
  Sphere to;                 // where the move goes
  std::vector<int> pressed;  // operation nodes near the ball's centre, pressed by the blade
};

// Paper scale: the built-in thigh (3128 tets), its 4 cm operation sphere as the ball, moved
// 2 cm round the tube.
const FollowCase& thigh_case() {
  static const FollowCase c = [] {
    FollowCase f;
    f.scene = make_thigh_scene();
    f.scene.operation_region.kind = OperationRegion::Kind::kFollow;
    const double a = 0.02 / 0.06;
    f.to = Sphere{Vec3(0.06 * std::cos(a), 0.06 * std::sin(a), 0.048), 0.04};
    return f;
  }();
  return c;
}

// Organ scale: config/scenes/liver_organ.yaml (sofa_liver2.obj at 0.08, TetGen pq1.4a2e-4Q,
// ~65k tets) with its 2 cm operation sphere as a `follow` ball, moved 2 cm along +x.
const FollowCase& liver_case() {
  static const FollowCase c = [] {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "stc_bench_follow";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "liver_organ_follow.yaml").string();
    std::ofstream(path) << "mesh: {file: " TISSUE_SHARED_MESH_DIR
                           "/sofa_liver2.obj, scale: 0.08, tetgen: {switches: \"pq1.4a2e-4Q\"}}\n"
                           "fixed: [{box: {min: [-0.2, -0.1, 1.0], max: [0.2, -0.055, 1.4]}}]\n"
                           "gravity: [0, -9.81, 0]\n"
                           "operation_region: {follow: {radius: 0.02}}\n"
                           "trajectory: [{t: 0, position: [-0.075, 0.0, 1.2069]}]\n";
    FollowCase f;
    f.scene = load_scene(path);
    f.to = Sphere{Vec3(-0.055, 0.0, 1.2069), 0.02};
    return f;
  }();
  return c;
}

const FollowCase& pick(int which) { return which == 0 ? thigh_case() : liver_case(); }
const char* name(int which) { return which == 0 ? "thigh (paper scale)" : "liver (organ scale)"; }

// One move as the worker runs it: the moved model from the current one, element matrices
// re-used.
void BM_RegionMove(benchmark::State& state) {
  const FollowCase& c = pick(static_cast<int>(state.range(0)));
  const HybridModel from(c.scene);
  const auto labels = follow_region_labels(from.mesh(), c.to, {});
  std::map<std::string, double> stages;
  for (auto _ : state) {
    HybridModel moved(from, labels);
    benchmark::DoNotOptimize(moved.hybrid_rhs().data());
    stages = moved.precompute_timings_ms();
  }
  for (const auto& [stage, ms] : stages) state.counters[stage + "_ms"] = ms;
  state.SetLabel(std::string(name(static_cast<int>(state.range(0)))) + ", " +
                 std::to_string(from.mesh().num_tets()) + " tets");
}
BENCHMARK(BM_RegionMove)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->Iterations(1);

// The same partition built from scratch (element matrices recomputed, partition from the
// region): what a move would cost without re-use.
void BM_RegionMoveFromScratch(benchmark::State& state) {
  const FollowCase& c = pick(static_cast<int>(state.range(0)));
  Scene moved_scene = c.scene;
  moved_scene.operation_region.sphere = c.to;
  double element_ms = 0;
  for (auto _ : state) {
    HybridModel fresh(moved_scene);
    benchmark::DoNotOptimize(fresh.hybrid_rhs().data());
    element_ms = fresh.precompute_timings_ms().at("element_stiffness");
  }
  state.counters["element_stiffness_ms"] = element_ms;
  state.SetLabel(name(static_cast<int>(state.range(0))));
}
BENCHMARK(BM_RegionMoveFromScratch)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->Iterations(1);

// A pressing step's solve (contact displacements on three nodes, warm CG + surface
// recovery), alone (arg1 = 0) or while a move re-condenses on the other core (arg1 = 1):
// median per solve over the move's duration.
void BM_StepDuringMove(benchmark::State& state) {
  const FollowCase& c = pick(static_cast<int>(state.range(0)));
  const bool moving = state.range(1) != 0;
  HybridModel model(c.scene);
  std::vector<int> pressed;
  const Vec3 centre = c.scene.operation_region.sphere.center;
  std::vector<std::pair<double, int>> near;
  for (int n : model.partition().operation)
    near.emplace_back((model.mesh().nodes[n] - centre).norm(), n);
  std::sort(near.begin(), near.end());
  for (int k = 0; k < 3 && k < static_cast<int>(near.size()); ++k)
    pressed.push_back(near[k].second);
  const auto labels = follow_region_labels(model.mesh(), c.to, {});
  std::vector<double> step_ms;
  int k = 0;
  for (auto _ : state) {
    std::future<void> worker;
    if (moving) worker = std::async(std::launch::async, [&] { HybridModel moved(model, labels); });
    const auto t_end = std::chrono::steady_clock::now() + std::chrono::milliseconds(300);
    do {  // steps for the move's duration (or 300 ms alone)
      ImposedDisplacements contact;
      const double depth = 1e-4 * (1 + (k++ % 20));  // the blade pressing in and out
      for (int n : pressed) contact[n] = Vec3(0, -depth, 0);
      const auto t0 = std::chrono::steady_clock::now();
      model.solve(contact);
      step_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    } while (moving ? worker.wait_for(std::chrono::seconds(0)) != std::future_status::ready
                    : std::chrono::steady_clock::now() < t_end);
    if (moving) worker.get();
  }
  std::sort(step_ms.begin(), step_ms.end());
  state.counters["solve_median_ms"] = step_ms[step_ms.size() / 2];
  state.counters["solve_p90_ms"] = step_ms[step_ms.size() * 9 / 10];
  state.counters["solve_max_ms"] = step_ms.back();
  state.counters["steps"] = static_cast<double>(step_ms.size());
  state.SetLabel(std::string(name(static_cast<int>(state.range(0)))) +
                 (moving ? ", move running" : ", no move"));
}
BENCHMARK(BM_StepDuringMove)
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// A stroke played online as the node plays it: one step every 10 ms (100 Hz), moves on the
// worker, no step waiting for one (docs/DESIGN.md section 10a, "Swap"). Paper scale:
// config/scenes/thigh_follow.yaml (7k tets, 2.5 cm ball), pressed in and drawn 10 cm at
// 0.5 mm per step; organ scale: the liver above (2 cm ball), pressed 1 cm in and drawn 4 cm
// at 0.05 mm per step (5 mm/s). Counters: every step's wall time (median, p90, max), the
// steps that swapped a moved region in and those that cut (median, max; and the medians of a
// cutting step's phases: collision, insertion, model update, solve), how far the cut lagged
// behind the blade and the longest catch-up after a move, moves, tets added.
void BM_OnlineFollowStroke(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  Scene scene;
  std::vector<BladePose> poses;
  auto line = [&poses](const Vec3& a, const Vec3& b, int steps, const Eigen::Quaterniond& q) {
    for (int k = 1; k <= steps; ++k) {
      BladePose p;
      p.position = a + (b - a) * (static_cast<double>(k) / steps);
      p.orientation = q;
      poses.push_back(p);
    }
  };
  if (which == 0) {
    scene = load_scene(TISSUE_SHARED_MESH_DIR "/../scenes/thigh_follow.yaml");
    const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // edge radially out (+x)
    const double x_in = 0.06 - 0.012;
    line(Vec3(0.065, 0.003, 0.02), Vec3(0.065, 0.003, 0.02), 1, q);
    line(Vec3(0.065, 0.003, 0.02), Vec3(x_in, 0.003, 0.02), 17, q);
    line(Vec3(x_in, 0.003, 0.02), Vec3(x_in, 0.003, 0.12), 200, q);
    line(Vec3(x_in, 0.003, 0.12), Vec3(0.07, 0.003, 0.12), 20, q);
  } else {
    scene = liver_case().scene;
    const Eigen::Quaterniond q(0.5, 0.5, 0.5, 0.5);  // edge up (+y), blade normal +z
    const Vec3 above(-0.092, 0.012, 1.2069), in(-0.092, -0.010, 1.2069);
    line(above, above, 1, q);
    line(above, in, 30, q);
    line(in, in + Vec3(0.04, 0, 0), 800, q);
    line(in + Vec3(0.04, 0, 0), in + Vec3(0.04, 0.022, 0), 20, q);
  }
  std::vector<double> steps, swaps, cuts;
  // Where a cutting step goes: its phases' medians (Simulation's StepStats).
  std::vector<double> cut_collision, cut_insertion, cut_update, cut_solve;
  int moves = 0, tets_added = 0;
  // How far the cut lags behind the blade (StepStats::cut_lag), and the longest catch-up: the
  // steps in a row with sweeps still waiting and no move under way (cutting the backlog a
  // move left, waiting_cut_budget_ms a step).
  double lag_max = 0;
  int catch_up = 0, catch_up_max = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Simulation sim(scene);
    const int tets = sim.counts().tets;
    state.ResumeTiming();
    auto next = std::chrono::steady_clock::now();
    for (const BladePose& pose : poses) {
      next += std::chrono::milliseconds(10);
      const StepStats s = sim.step(pose);
      steps.push_back(s.step_ms);
      lag_max = std::max(lag_max, s.cut_lag);
      catch_up = s.sweeps_waiting > 0 && !s.region_moving ? catch_up + 1 : 0;
      catch_up_max = std::max(catch_up_max, catch_up);
      if (s.region_moved) swaps.push_back(s.step_ms);
      if (s.cutting) {
        cuts.push_back(s.step_ms);
        cut_collision.push_back(s.collision_ms);
        cut_insertion.push_back(s.cutting_ms);
        cut_update.push_back(s.assembly_ms);
        cut_solve.push_back(s.solve_ms);
      }
      std::this_thread::sleep_until(next);
    }
    moves = sim.region_moves()->moves;
    tets_added = sim.counts().tets - tets;
  }
  auto at = [](std::vector<double> v, double f) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<size_t>(f * static_cast<double>(v.size())))];
  };
  state.counters["step_median_ms"] = at(steps, 0.5);
  state.counters["step_p90_ms"] = at(steps, 0.9);
  state.counters["step_max_ms"] = at(steps, 1.0);
  state.counters["swap_median_ms"] = at(swaps, 0.5);
  state.counters["swap_max_ms"] = at(swaps, 1.0);
  state.counters["cutting_median_ms"] = at(cuts, 0.5);
  state.counters["cutting_max_ms"] = at(cuts, 1.0);
  state.counters["cutting_collision_median_ms"] = at(cut_collision, 0.5);
  state.counters["cutting_insertion_median_ms"] = at(cut_insertion, 0.5);
  state.counters["cutting_model_update_median_ms"] = at(cut_update, 0.5);
  state.counters["cutting_solve_median_ms"] = at(cut_solve, 0.5);
  state.counters["cut_lag_max_mm"] = 1e3 * lag_max;
  state.counters["catch_up_steps_max"] = catch_up_max;
  state.counters["moves"] = moves;
  state.counters["tets_added"] = tets_added;
  state.SetLabel(which == 0 ? "thigh_follow (paper scale), 0.5 mm per 10 ms step"
                            : "liver (organ scale), 0.05 mm per 10 ms step");
}
BENCHMARK(BM_OnlineFollowStroke)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace stc
