#include "scene_timing.hpp"

#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/model_counts_json.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/simulation/step_times.hpp"

#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace stc {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The scene's trajectory with extra poses so the blade travels at most step_m per step (the
// rate a tracked instrument sends poses at).
std::vector<BladePose> substepped(const std::vector<BladePose>& p, double step_m) {
  std::vector<BladePose> out;
  for (size_t i = 0; i + 1 < p.size(); ++i) {
    const double len = (p[i + 1].position - p[i].position).norm();
    const int k = std::max(1, static_cast<int>(std::ceil(len / step_m)));
    for (int j = 0; j < k; ++j) {
      BladePose b = p[i];
      const double s = static_cast<double>(j) / k;
      b.position = (1 - s) * p[i].position + s * p[i + 1].position;
      b.orientation = p[i].orientation.slerp(s, p[i + 1].orientation);
      out.push_back(b);
    }
  }
  if (!p.empty()) out.push_back(p.back());
  return out;
}

nlohmann::json summary(const std::vector<double>& ms) {
  const StepTimeSummary s = summarize_step_times(ms);
  return {{"n", s.n}, {"median", s.median}, {"max", s.max}};
}

// Processor time of this process (all its threads): on a machine shared with other jobs it
// moves far less than wall time, so before/after ratios are read from it.
double cpu_ms_now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

}  // namespace

nlohmann::json time_hybrid(const BenchCase& c, double step_m, int idle_steps) {
  nlohmann::json j;
  auto t0 = Clock::now();
  const Scene scene = c.load();
  j["mesh_ms"] = ms_since(t0);  // reading / TetGen, not part of the precompute
  t0 = Clock::now();
  double c0 = cpu_ms_now();
  Simulation sim(scene);
  j["precompute_ms"] = ms_since(t0);  // condensation + hybrid factor + initial equilibrium
  nlohmann::json cpu;
  cpu["precompute"] = cpu_ms_now() - c0;
  j["name"] = c.name;
  add_model_sizes(j, sim.counts());

  // Idle: no blade, nothing changed since the last step.
  std::vector<double> idle, idle_cpu;
  for (int k = 0; k < idle_steps; ++k) {
    c0 = cpu_ms_now();
    idle.push_back(sim.step(std::nullopt).step_ms);
    idle_cpu.push_back(cpu_ms_now() - c0);
  }

  // The trajectory; the first pressing step's constraint is kept for the full model.
  const std::vector<BladePose> poses = substepped(scene.trajectory, step_m);
  std::vector<double> pressing, cutting, refresh, pressing_cpu, cutting_cpu;
  // Where a cutting step's time goes (StepStats stages, docs/DESIGN.md section 10).
  std::vector<double> cut_collision, cut_insertion, cut_model_update, cut_solve;
  std::vector<double> press_collision, press_solve;
  bool recorded = false;
  for (const BladePose& p : poses) {
    c0 = cpu_ms_now();
    const StepStats s = sim.step(p);
    const double step_cpu = cpu_ms_now() - c0;
    if (step_kind(s) == StepKind::kCutting) cutting_cpu.push_back(step_cpu);
    if (step_kind(s) == StepKind::kPressing) pressing_cpu.push_back(step_cpu);
    if (step_kind(s) != StepKind::kIdle) {
      // The visible surface as a display would fetch it after this step (u_S recovered from
      // u_I through the factor of K2_NN): timed apart, it is not part of the step.
      const auto tr = Clock::now();
      const DeformedSurface drawn = sim.surface();
      refresh.push_back(ms_since(tr));
      if (drawn.positions.empty()) throw std::runtime_error("empty surface");
    }
    if (step_kind(s) == StepKind::kCutting) {
      cutting.push_back(s.step_ms);
      cut_collision.push_back(s.collision_ms);
      cut_insertion.push_back(s.cutting_ms);
      cut_model_update.push_back(s.assembly_ms);
      cut_solve.push_back(s.solve_ms);
    }
    if (step_kind(s) == StepKind::kPressing) {
      pressing.push_back(s.step_ms);
      press_collision.push_back(s.collision_ms);
      press_solve.push_back(s.solve_ms);
      if (!recorded && sim.counts().cuts == 0) {
        // The three mesh nodes nearest the tip (deformed) with their displacements: the
        // same kind and size of constraint as the blade's contact triangle.
        const Vector& u = sim.model().displacement();
        const auto& fixed = sim.model().fixed_nodes();
        std::vector<std::pair<double, int>> d;
        for (int n = 0; n < sim.mesh().num_nodes(); ++n)
          if (!fixed[static_cast<size_t>(n)])
            d.emplace_back((sim.mesh().nodes[n] + u.segment<3>(3 * n) - p.position).norm(), n);
        std::partial_sort(d.begin(), d.begin() + 3, d.end());
        nlohmann::json nodes = nlohmann::json::array(), disp = nlohmann::json::array();
        for (int k = 0; k < 3; ++k) {
          const int n = d[static_cast<size_t>(k)].second;
          nodes.push_back(n);
          disp.push_back({u[3 * n], u[3 * n + 1], u[3 * n + 2]});
        }
        j["press_nodes"] = nodes;
        j["press_u"] = disp;
        recorded = true;
      }
    }
  }
  const StepTimeSummary si = summarize_step_times(idle), sp = summarize_step_times(pressing),
                        sc = summarize_step_times(cutting);
  j["idle_step_ms_median"] = si.median;
  j["step_ms_median"] = sp.median;
  j["cut_step_ms_median"] = sc.median;
  j["cut_step_ms_max"] = sc.max;
  j["idle"] = summary(idle);
  j["pressing"] = summary(pressing);
  j["cutting"] = summary(cutting);
  j["surface_refresh_ms"] = summary(refresh);
  j["cut_step_stages_ms_median"] = {{"collision", summarize_step_times(cut_collision).median},
                                    {"cut_insertion", summarize_step_times(cut_insertion).median},
                                    {"model_update", summarize_step_times(cut_model_update).median},
                                    {"solve_with_factor", summarize_step_times(cut_solve).median}};
  j["step_stages_ms_median"] = {{"collision", summarize_step_times(press_collision).median},
                                {"solve", summarize_step_times(press_solve).median}};
  cpu["idle_step_median"] = summarize_step_times(idle_cpu).median;
  cpu["step_median"] = summarize_step_times(pressing_cpu).median;
  cpu["cut_step_median"] = summarize_step_times(cutting_cpu).median;
  cpu["cut_step_max"] = summarize_step_times(cutting_cpu).max;
  j["cpu_ms"] = cpu;
  j["cuts"] = sim.counts().cuts;
  j["tets_after"] = sim.mesh().num_tets();
  j["trajectory_steps"] = poses.size();
  return j;
}

nlohmann::json time_full(const BenchCase& c, const nlohmann::json& hybrid, int repetitions) {
  nlohmann::json j;
  if (!hybrid.contains("press_nodes")) {
    j["full_solve_ms_median"] = 0.0;
    j["full_note"] = "no pressing step before the first cut";
    return j;
  }
  const Scene scene = c.load();
  auto t0 = Clock::now();
  const FullModel full = assemble_full_model(scene);
  std::unique_ptr<LinearSolver> solver = make_cpu_solver();  // Cholesky-preconditioned CG
  solver->set_matrix(full.K);
  j["full_precompute_ms"] = ms_since(t0);
  j["full_dof"] = full.dofs.rows();
  const CgSettings settings{scene.solver.tolerance, scene.solver.max_iterations};
  // The equilibrium before the press (warm start, as the hybrid step has it).
  Vector rest = Vector::Zero(full.dofs.rows());
  solver->solve(full.f, rest, {}, settings);
  std::vector<std::uint8_t> constrained(static_cast<size_t>(full.dofs.rows()), 0);
  Vector start = rest;
  for (size_t k = 0; k < hybrid["press_nodes"].size(); ++k) {
    const int n = hybrid["press_nodes"][k].get<int>();
    for (int d = 0; d < 3; ++d) {
      const int r = full.dofs.row_of[static_cast<size_t>(3 * n + d)];
      if (r < 0) continue;
      start[r] = hybrid["press_u"][k][d].get<double>();
      constrained[static_cast<size_t>(r)] = 1;
    }
  }
  std::vector<double> ms, cpu;
  int iterations = 0;
  for (int k = 0; k < repetitions; ++k) {
    Vector x = start;
    t0 = Clock::now();
    const double c0 = cpu_ms_now();
    const CgResult r = solver->solve(full.f, x, constrained, settings);
    cpu.push_back(cpu_ms_now() - c0);
    ms.push_back(ms_since(t0));
    iterations = r.iterations;
  }
  j["full_solve_ms_median"] = summarize_step_times(ms).median;
  // The CPU solver keeps A^-1 b and A^-1 e_c of held DOFs per matrix (docs/DESIGN.md eqs.
  // (24)-(25)): repetitions 2.. reuse them, the first one pays for them.
  j["full_solve_ms_first"] = ms.front();
  j["full_solve_cpu_ms_first"] = cpu.front();
  j["full_solve_cpu_ms_median"] = summarize_step_times(cpu).median;
  j["full_cg_iterations"] = iterations;
  return j;
}

nlohmann::json in_child(const std::function<nlohmann::json()>& work) {
  char path[] = "/tmp/tissue_bench_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) throw std::runtime_error("bench: cannot create a temporary file");
  close(fd);
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("bench: fork failed");
  if (pid == 0) {
    int rc = 0;
    try {
      std::ofstream(path) << work().dump();
    } catch (const std::exception& e) {
      std::ofstream(path) << nlohmann::json{{"error", e.what()}}.dump();
      rc = 1;
    }
    std::fflush(stdout);
    _exit(rc);
  }
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::remove(path);
  nlohmann::json j = ss.str().empty() ? nlohmann::json{{"error", "the child process died"}}
                                      : nlohmann::json::parse(ss.str());
  j["peak_rss_mb"] = static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kB
  return j;
}

}  // namespace stc
