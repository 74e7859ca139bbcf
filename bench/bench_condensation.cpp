// The paper's Table 1 on the built-in thigh (make_thigh_scene(): 3128 tets, ~2170 of them in
// the non-operation part): the per-step solve of the condensed (hybrid) model - projected CG
// on eq. 17 plus the surface recovery u_S = c_S + R u_I - against the general uncondensed
// model's per-step solve - projected CG on the full K. Like with like: same tolerance, and
// BOTH sides use the same CG preconditioner (the benchmark argument, in the name and label):
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

namespace stc {
namespace {

constexpr double kTolerance = 1e-10;  // the thigh scene's solver.tolerance

const Scene& thigh() {
  static const Scene s = make_thigh_scene();
  return s;
}
int contact_node() { return thigh().loads[0].where.nodes[0]; }

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
  HybridModel h(thigh(), make_cpu_solver(preconditioner(state)));
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
  label(state, "condensed (hybrid eq. 17)", h.solver());
}

void BM_Table1_GeneralStep_Cold(benchmark::State& state) {
  const FullModel m = assemble_full_model(thigh());
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
  HybridModel h(thigh(), make_cpu_solver(preconditioner(state)));
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
  label(state, "condensed (hybrid eq. 17)", h.solver());
}

void BM_Table1_GeneralStep_WarmContact(benchmark::State& state) {
  const FullModel m = assemble_full_model(thigh());
  auto cg = make_cpu_solver(preconditioner(state));
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
  label(state, "general (full K)", *cg);
}

// What a cut (or an E change) costs the solver: set_matrix on the hybrid / the full matrix.
void BM_Table1_CondensedFactor(benchmark::State& state) {
  const HybridModel h(thigh());
  auto cg = make_cpu_solver(preconditioner(state));
  for (auto _ : state) cg->set_matrix(h.hybrid_matrix());
  state.counters["dof"] = static_cast<double>(h.hybrid_matrix().rows());
  state.counters["nnz"] = static_cast<double>(h.hybrid_matrix().nonZeros());
  label(state, "condensed set_matrix", *cg);
}

void BM_Table1_GeneralFactor(benchmark::State& state) {
  const FullModel m = assemble_full_model(thigh());
  auto cg = make_cpu_solver(preconditioner(state));
  for (auto _ : state) cg->set_matrix(m.K);
  state.counters["dof"] = static_cast<double>(m.K.rows());
  state.counters["nnz"] = static_cast<double>(m.K.nonZeros());
  label(state, "general set_matrix", *cg);
}

// Arg 0: Jacobi, arg 1: Cholesky (the name shows it as precond:0 / precond:1).
#define STC_TABLE1(fn)                                                                   \
  BENCHMARK(fn)->ArgName("precond")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)      \
      ->Repetitions(15)->ReportAggregatesOnly(true)
BENCHMARK(BM_Precompute)->Unit(benchmark::kMillisecond)->Repetitions(15)
    ->ReportAggregatesOnly(true);
STC_TABLE1(BM_Table1_CondensedStep_Cold);
STC_TABLE1(BM_Table1_GeneralStep_Cold);
STC_TABLE1(BM_Table1_CondensedStep_WarmContact);
STC_TABLE1(BM_Table1_GeneralStep_WarmContact);
STC_TABLE1(BM_Table1_CondensedFactor);
STC_TABLE1(BM_Table1_GeneralFactor);

}  // namespace
}  // namespace stc
