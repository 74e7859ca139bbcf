// The paper's Table 1 on the built-in thigh (make_thigh_scene(): 3128 tets, ~2170 of them in
// the non-operation part): the per-step solve of the condensed (hybrid) model - projected CG
// on docs/DESIGN.md eq. (10) plus the surface recovery u_S = c_S + R u_I - against the general
// uncondensed model's per-step solve - projected CG on the full K. Like with like: same tolerance,
// and BOTH sides use the same CG preconditioner (the benchmark argument, in the name and label):
//   jacobi:   the paper's plain-CG setting (diagonal scaling only);
//   cholesky: M = P A^-1 P, A factored once per matrix (solve/linear_solver.hpp).
//   *_Cold: both start from zero every step (the paper's setting: a full static solve).
//   *_WarmContact: a contact node is pushed 10 um further each step, both warm-started from
//                  the previous step (the simulation loop).
//   *_Factor: set_matrix alone (Jacobi: copy + diagonal; Cholesky: the CHOLMOD factorization),
//             the cost paid whenever the matrix changes (every cut, every E change).
// Plus the one-off precompute (partition, element matrices, CHOLMOD condensation, R, K1+K0).
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>

namespace stc {
namespace {

constexpr double kTolerance = 1e-10;  // the thigh scene's solver.tolerance

// Arg "region": 0 = the built-in thigh (operation part refined for cutting: 958 tets, 115
// interface nodes); 1 = the paper-like setting, the structured 3 x 16 x 8 thigh with the same
// operation sphere left coarse (181 operation tets, 66 interface nodes, 2123 condensed tets),
// where the interface - and so the dense K0 block - is small.
Scene make_small_region_thigh() {
  Scene t = make_thigh_scene();  // material, region, loads' directions, solver
  GeneratorParams g;
  g.type = "thigh";
  g.resolution = 1.25;  // lround: 3 x 16 x 8 cells, no refinement
  t.mesh = make_thigh_mesh(g);
  t.fixed[0].nodes.clear();
  std::vector<std::pair<double, int>> outer;
  for (int i = 0; i < t.mesh.num_nodes(); ++i) {
    const Vec3& x = t.mesh.nodes[i];
    const double r = std::hypot(x.x(), x.y());
    if (r <= g.inner_radius * (1 + 1e-9)) t.fixed[0].nodes.push_back(i);
    if (r >= g.outer_radius * (1 - 1e-9))
      outer.emplace_back((x - t.operation_region.sphere.center).norm(), i);
  }
  std::sort(outer.begin(), outer.end());
  for (size_t k = 0; k < t.loads.size(); ++k) t.loads[k].where.nodes = {outer[k + 1].second};
  return t;
}

const Scene& thigh(int region = 0) {
  static const Scene refined = make_thigh_scene();
  static const Scene coarse = make_small_region_thigh();
  return region == 0 ? refined : coarse;
}
const Scene& thigh(const benchmark::State& state) {
  return thigh(static_cast<int>(state.range(1)));
}
int contact_node(const benchmark::State& state) { return thigh(state).loads[0].where.nodes[0]; }

CgPreconditioner preconditioner(const benchmark::State& state) {
  return state.range(0) == 0 ? CgPreconditioner::kJacobi : CgPreconditioner::kCholesky;
}
void label(benchmark::State& state, const char* model, const LinearSolver& s) {
  state.SetLabel(std::string(model) + ", both condensed and general with preconditioner " +
                 s.preconditioner());
}

void BM_Precompute(benchmark::State& state) {
  for (auto _ : state) {
    HybridModel h(thigh());
    benchmark::DoNotOptimize(h.hybrid_matrix().nonZeros());
    state.counters["condensation_ms"] = h.precompute_timings_ms().at("condensation_factor") +
                                        h.precompute_timings_ms().at("condensation_solve") +
                                        h.precompute_timings_ms().at("condensation_products");
  }
}

void BM_Table1_CondensedStep_Cold(benchmark::State& state) {
  HybridModel h(thigh(state), make_cpu_solver(preconditioner(state)));
  h.set_cg_settings(CgSettings{kTolerance, 20000});
  CgResult r;
  for (auto _ : state) {
    h.reset_displacement();
    r = h.solve();  // CG on docs/DESIGN.md eq. (10) + u_S = c_S + R u_I
    benchmark::DoNotOptimize(h.displacement().data());
  }
  state.counters["dof"] = h.counts().dof_operation;
  state.counters["cg_iterations"] = r.iterations;
  state.counters["converged"] = r.converged;
  label(state, "condensed (hybrid eq. 17)", h.solver());
}

void BM_Table1_GeneralStep_Cold(benchmark::State& state) {
  const FullModel m = assemble_full_model(thigh(state));
  auto cg = make_cpu_solver(preconditioner(state));
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
  label(state, "general (full K)", *cg);
}

void BM_Table1_CondensedStep_WarmContact(benchmark::State& state) {
  HybridModel h(thigh(state), make_cpu_solver(preconditioner(state)));
  h.set_cg_settings(CgSettings{kTolerance, 20000});
  h.solve();
  const int node = contact_node(state);
  double depth = 0;
  long iterations = 0, steps = 0;
  for (auto _ : state) {
    depth += 1e-5;
    const CgResult r = h.solve({{node, Vec3(-depth, 0, 0)}});
    iterations += r.iterations, ++steps;
    benchmark::DoNotOptimize(h.displacement().data());
  }
  state.counters["cg_iterations"] = static_cast<double>(iterations) / static_cast<double>(steps);
  label(state, "condensed (hybrid eq. 17)", h.solver());
}

void BM_Table1_GeneralStep_WarmContact(benchmark::State& state) {
  const FullModel m = assemble_full_model(thigh(state));
  auto cg = make_cpu_solver(preconditioner(state));
  cg->set_matrix(m.K);
  const int node = contact_node(state);
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
  label(state, "general (full K)", *cg);
}

// What a cut (or an E change) costs the solver: set_matrix on the hybrid / the full matrix.
void BM_Table1_CondensedFactor(benchmark::State& state) {
  const HybridModel h(thigh(state));
  auto cg = make_cpu_solver(preconditioner(state));
  for (auto _ : state) cg->set_matrix(h.hybrid_matrix());
  state.counters["dof"] = static_cast<double>(h.hybrid_matrix().rows());
  state.counters["nnz"] = static_cast<double>(h.hybrid_matrix().nonZeros());
  label(state, "condensed set_matrix", *cg);
}

void BM_Table1_GeneralFactor(benchmark::State& state) {
  const FullModel m = assemble_full_model(thigh(state));
  auto cg = make_cpu_solver(preconditioner(state));
  for (auto _ : state) cg->set_matrix(m.K);
  state.counters["dof"] = static_cast<double>(m.K.rows());
  state.counters["nnz"] = static_cast<double>(m.K.nonZeros());
  label(state, "general set_matrix", *cg);
}

// precond 0: Jacobi, 1: Cholesky; region 0: built-in thigh, 1: small (paper-like) region.
#define STC_TABLE1(fn)                  \
  BENCHMARK(fn)                         \
      ->ArgNames({"precond", "region"}) \
      ->ArgsProduct({{0, 1}, {0, 1}})   \
      ->Unit(benchmark::kMillisecond)   \
      ->Repetitions(15)                 \
      ->ReportAggregatesOnly(true)
BENCHMARK(BM_Precompute)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(15)
    ->ReportAggregatesOnly(true);
STC_TABLE1(BM_Table1_CondensedStep_Cold);
STC_TABLE1(BM_Table1_GeneralStep_Cold);
STC_TABLE1(BM_Table1_CondensedStep_WarmContact);
STC_TABLE1(BM_Table1_GeneralStep_WarmContact);
STC_TABLE1(BM_Table1_CondensedFactor);
STC_TABLE1(BM_Table1_GeneralFactor);

}  // namespace
}  // namespace stc
