// Whole simulation steps on the built-in thigh (docs/DESIGN.md section 10): the scripted scalpel
// presses and then cuts. A cutting step = collision + cut insertion + re-assembly of the changed
// tets + hybrid CG solve + surface recovery. Median and max over every cutting step of the stroke,
// and tets added per cm of cut. (Issue 4's target: median under 5 ms on one core.) A cutting
// step's solver share: CG iterations, and set_matrix (the Cholesky preconditioner's
// factorization of the changed hybrid matrix) inside assembly_ms.
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>

namespace stc {
namespace {

// The thigh trajectory at `substeps` poses per segment, as the trajectory player sends it.
std::vector<BladePose> stroke(const Scene& scene, int substeps) {
  std::vector<BladePose> out;
  const auto& p = scene.trajectory;
  for (size_t i = 0; i + 1 < p.size(); ++i)
    for (int k = 0; k < substeps; ++k) {
      const double s = static_cast<double>(k) / substeps;
      BladePose b = p[i];
      b.position = (1 - s) * p[i].position + s * p[i + 1].position;
      out.push_back(b);
    }
  out.push_back(p.back());
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

void BM_ThighStrokeSteps(benchmark::State& state) {
  const Scene scene = make_thigh_scene();
  const auto poses = stroke(scene, static_cast<int>(state.range(0)));
  Simulation sim(scene);
  std::vector<double> cutting_ms, pressing_ms, cut_factor_ms, cut_iterations, press_iterations;
  double cut_length_cm = 0;
  int tets_added = 0;
  for (auto _ : state) {
    state.PauseTiming();
    sim.reset();
    const int tets0 = sim.mesh().num_tets();
    state.ResumeTiming();
    // Cut length: the blade's travel from its first to its last cutting step (steps in
    // between that split nothing still move the blade through the tissue).
    double travelled_cm = 0, travelled_at_first_cut = -1, travelled_at_last_cut = 0;
    std::optional<BladePose> previous;
    for (const BladePose& p : poses) {
      if (previous) travelled_cm += 100 * (p.position - previous->position).norm();
      const auto t0 = std::chrono::steady_clock::now();
      const StepStats s = sim.step(p);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      if (s.cutting) {
        cutting_ms.push_back(ms);
        cut_factor_ms.push_back(sim.model().solver().setup_ms());
        cut_iterations.push_back(s.cg_iterations);
        if (travelled_at_first_cut < 0) travelled_at_first_cut = travelled_cm;
        travelled_at_last_cut = travelled_cm;
      } else if (s.in_contact) {
        pressing_ms.push_back(ms);
        press_iterations.push_back(s.cg_iterations);
      }
      previous = p;
    }
    state.PauseTiming();
    if (travelled_at_first_cut >= 0)
      cut_length_cm += travelled_at_last_cut - travelled_at_first_cut;
    tets_added += sim.mesh().num_tets() - tets0;
    state.ResumeTiming();
  }
  state.counters["cut_step_median_ms"] = median(cutting_ms);
  state.counters["cut_step_max_ms"] =
      cutting_ms.empty() ? 0 : *std::max_element(cutting_ms.begin(), cutting_ms.end());
  state.counters["cut_step_factor_median_ms"] = median(cut_factor_ms);
  state.counters["cut_step_cg_median"] = median(cut_iterations);
  state.counters["press_step_median_ms"] = median(pressing_ms);
  state.counters["press_step_cg_median"] = median(press_iterations);
  state.counters["cut_steps_per_stroke"] =
      static_cast<double>(cutting_ms.size()) / static_cast<double>(state.iterations());
  state.counters["tets_added_per_cm"] = cut_length_cm > 0 ? tets_added / cut_length_cm : 0;
  state.SetLabel("thigh " + std::to_string(scene.mesh.num_tets()) + " tets, hybrid DOF " +
                 std::to_string(sim.counts().dof_operation) + ", " +
                 sim.model().solver().backend() + " CG, preconditioner " +
                 sim.model().solver().preconditioner());
}
// 10 and 40 poses per trajectory segment: 2 mm and 0.5 mm of blade travel per step.
BENCHMARK(BM_ThighStrokeSteps)->Arg(10)->Arg(40)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stc
