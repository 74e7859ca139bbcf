// Cutting on the thigh (issue 4): one cutting sweep = collision query (surface BVH refit and
// the blade's edge contact, collision/edge_contact) + cut insertion (split, mark, separate), on the
// scripted scalpel's drawing stroke through the operation region. Counter: tets added per cm of
// cut.
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "soft_tissue_cutting/collision/edge_contact.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"

#include <benchmark/benchmark.h>

#include <optional>

namespace stc {
namespace {

struct ThighCut {
  Scene scene = make_thigh_scene();
  std::vector<std::uint8_t> cuttable;
  ThighCut() {
    cuttable.resize(scene.mesh.tets.size());
    for (int t = 0; t < scene.mesh.num_tets(); ++t) {
      Vec3 c = Vec3::Zero();
      for (int v : scene.mesh.tets[t]) c += scene.mesh.nodes[v] / 4;
      cuttable[t] = scene.operation_region.contains(c);
    }
  }
};

// The scripted stroke, split into `steps` sweeps (one per simulation step).
void BM_CuttingSweep(benchmark::State& state) {
  const ThighCut thigh;
  const int steps = static_cast<int>(state.range(0));
  const auto& poses = thigh.scene.trajectory;  // poses 2 -> 4: the draw along z
  const double length = thigh.scene.scalpel.blade_length;
  const BladeEdge start = blade_edge(poses[2], length), end = blade_edge(poses[4], length);
  auto edge_at = [&](double s) {
    BladeEdge e;
    e.tip = start.tip + s * (end.tip - start.tip);
    e.heel = start.heel + s * (end.heel - start.heel);
    return e;
  };
  const double cut_cm = (end.tip - start.tip).norm() * 100;
  long tets_added = 0, sweeps = 0;
  for (auto _ : state) {
    state.PauseTiming();
    TetMesh mesh = thigh.scene.mesh;
    CutState cut = make_cut_state(mesh, {}, thigh.cuttable);
    SurfaceBvh bvh;
    bvh.build(mesh, thigh.cuttable, {});
    EdgeContact contact;
    std::optional<BladeEdge> previous;
    const int tets_before = mesh.num_tets();
    state.ResumeTiming();
    for (int k = 0; k < steps; ++k) {
      const BladeEdge from = edge_at(static_cast<double>(k) / steps),
                      to = edge_at(static_cast<double>(k + 1) / steps);
      bvh.refit(mesh, std::vector<Vec3>{});
      const Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
      benchmark::DoNotOptimize(contact.update(bvh, mesh, u, previous, to));
      previous = to;
      const CutResult r = cut_sweep(mesh, cut, from, to);
      if (r.nodes_added > 0) bvh.build(mesh, cut.cuttable, {});  // the surface changed
    }
    state.PauseTiming();
    tets_added += mesh.num_tets() - tets_before;
    ++sweeps;
    state.ResumeTiming();
  }
  state.counters["sweeps_per_stroke"] = steps;
  state.counters["tets_added_per_cm"] = static_cast<double>(tets_added) / sweeps / cut_cm;
  // Seconds per sweep (shown with an SI prefix, e.g. 380u = 0.38 ms).
  state.counters["s_per_sweep"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsIterationInvariantRate |
                                                         benchmark::Counter::kInvert);
}
// 1 sweep for the whole 4 cm stroke, and 20 sweeps of 2 mm (a 100 Hz loop at 20 cm/s).
BENCHMARK(BM_CuttingSweep)
    ->Arg(1)
    ->Arg(20)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace stc
