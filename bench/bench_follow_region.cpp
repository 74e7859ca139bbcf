// The operation region that follows the scalpel (simulation/region_follower.hpp): how long a
// move takes (re-partition + re-condensation of part 2 + hybrid assembly and factorization, as
// the worker thread runs it) at paper scale (the built-in thigh) and on the organ-scale liver
// of config/scenes/liver_organ.yaml (its 2 cm sphere made a `follow` ball); the same model built
// from scratch (element matrices recomputed) for the gain of re-using them; and the per-step solve
// while a move runs on the other core.
#include "simulation/region_follower.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/partition/follow_region.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>

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

}  // namespace
}  // namespace stc
