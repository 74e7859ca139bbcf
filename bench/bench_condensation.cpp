// The paper's Table 1 on the built-in thigh (make_thigh_scene(): 2304 tets, 2123 of them in
// the non-operation part, cf. the paper's 2134): the per-step solve of the condensed
// (hybrid) model - CG on eq. 17 plus the surface recovery u_S = c_S + R u_I - against the
// general uncondensed model's per-step solve - CG on the full K - same tolerance.
//   *_Cold: both start from zero every step (the paper's setting: a full static solve).
//   *_WarmContact: a contact node is pushed 10 um further each step, both warm-started from
//                 the previous step (the simulation loop).
// Plus the one-off precompute (partition, element matrices, CHOLMOD condensation, R, K1+K0).
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"

#include <benchmark/benchmark.h>

namespace stc {
namespace {

constexpr double kTolerance = 1e-10;  // the thigh scene's solver.tolerance

const Scene& thigh() {
  static const Scene s = make_thigh_scene();
  return s;
}
int contact_node() { return thigh().loads[0].where.nodes[0]; }

void BM_Precompute(benchmark::State& state) {
  for (auto _ : state) {
    HybridModel h(thigh());
    benchmark::DoNotOptimize(h.hybrid_matrix().nonZeros());
    state.counters["condensation_ms"] = h.precompute_timings_ms().at("condensation_factor") +
                                        h.precompute_timings_ms().at("condensation_solve") +
                                        h.precompute_timings_ms().at("condensation_products");
  }
}

void BM_CondensedStep_Cold(benchmark::State& state) {
  HybridModel h(thigh());
  h.set_cg_settings(CgSettings{kTolerance, 20000});
  CgResult r;
  for (auto _ : state) {
    h.reset_displacement();
    r = h.solve();  // CG on eq. 17 + u_S = c_S + R u_I
    benchmark::DoNotOptimize(h.displacement().data());
  }
  state.counters["dof"] = h.counts().dof_operation;
  state.counters["cg_iterations"] = r.iterations;
  state.counters["converged"] = r.converged;
}

void BM_GeneralStep_Cold(benchmark::State& state) {
  const FullModel m = assemble_full_model(thigh());
  auto cg = make_cpu_solver();
  cg->set_matrix(m.K);
  CgResult r;
  for (auto _ : state) {
    Vector x = Vector::Zero(m.K.rows());
    r = cg->solve(m.f, x, {}, CgSettings{kTolerance, 20000});
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["dof"] = static_cast<double>(m.K.rows());
  state.counters["cg_iterations"] = r.iterations;
  state.counters["converged"] = r.converged;
}

void BM_CondensedStep_WarmContact(benchmark::State& state) {
  HybridModel h(thigh());
  h.set_cg_settings(CgSettings{kTolerance, 20000});
  h.solve();
  const int node = contact_node();
  double depth = 0;
  long iterations = 0, steps = 0;
  for (auto _ : state) {
    depth += 1e-5;
    const CgResult r = h.solve({{node, Vec3(-depth, 0, 0)}});
    iterations += r.iterations, ++steps;
    benchmark::DoNotOptimize(h.displacement().data());
  }
  state.counters["cg_iterations"] = static_cast<double>(iterations) / static_cast<double>(steps);
}

void BM_GeneralStep_WarmContact(benchmark::State& state) {
  const FullModel m = assemble_full_model(thigh());
  auto cg = make_cpu_solver();
  cg->set_matrix(m.K);
  const int node = contact_node();
  std::vector<std::uint8_t> constrained(static_cast<size_t>(m.K.rows()), 0);
  for (int c = 0; c < 3; ++c) constrained[static_cast<size_t>(m.dofs.row_of[3 * node + c])] = 1;
  Vector x = Vector::Zero(m.K.rows());
  cg->solve(m.f, x, {}, CgSettings{kTolerance, 20000});
  double depth = 0;
  long iterations = 0, steps = 0;
  for (auto _ : state) {
    depth += 1e-5;
    for (int c = 0; c < 3; ++c) x[m.dofs.row_of[3 * node + c]] = c == 0 ? -depth : 0.0;
    const CgResult r = cg->solve(m.f, x, constrained, CgSettings{kTolerance, 20000});
    iterations += r.iterations, ++steps;
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["cg_iterations"] = static_cast<double>(iterations) / static_cast<double>(steps);
}

#define STC_TABLE1(fn) \
  BENCHMARK(fn)->Unit(benchmark::kMillisecond)->Repetitions(15)->ReportAggregatesOnly(true)
STC_TABLE1(BM_Precompute);
STC_TABLE1(BM_CondensedStep_Cold);
STC_TABLE1(BM_GeneralStep_Cold);
STC_TABLE1(BM_CondensedStep_WarmContact);
STC_TABLE1(BM_GeneralStep_WarmContact);

}  // namespace
}  // namespace stc
