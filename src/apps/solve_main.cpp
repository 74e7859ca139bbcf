// ./tissue solve SCENE.yaml [--out OUT.vtk] [--stats OUT.json] [--backend cpu|gl]
// The offline run of docs/SCENE.md "Offline run": load, precompute the condensation, play the
// scene's trajectory (pressure-triggered cuts included), solve the final equilibrium, write
// outputs.
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/simulation/step_times.hpp"
#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

namespace {

int usage(const char* why) {
  std::fprintf(stderr,
               "tissue solve: %s\nusage: tissue solve SCENE.yaml [--out OUT.vtk] "
               "[--stats OUT.json] [--backend cpu|gl]\n",
               why);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  stc::reexec_with_native_blas_kernels(argv);  // before anything runs (blas_kernels.hpp)
  std::string scene_path, out, stats, backend;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](std::string& into) {
      if (i + 1 >= argc) return false;
      into = argv[++i];
      return true;
    };
    if (arg == "--out") {
      if (!value(out)) return usage("--out needs a path");
    } else if (arg == "--stats") {
      if (!value(stats)) return usage("--stats needs a path");
    } else if (arg == "--backend") {
      if (!value(backend)) return usage("--backend needs cpu or gl");
      if (!stc::parse_backend(backend)) return usage("--backend must be cpu or gl");
    } else if (!arg.empty() && arg[0] == '-') {
      return usage(("unknown option " + arg).c_str());
    } else if (scene_path.empty()) {
      scene_path = arg;
    } else {
      return usage(("unexpected argument " + arg).c_str());
    }
  }
  if (scene_path.empty()) return usage("missing SCENE.yaml");

  const auto t0 = std::chrono::steady_clock::now();
  try {
    stc::SimulationOptions options;
    if (!backend.empty()) options.backend = stc::parse_backend(backend);
    options.gl = stc::gl_context_options_from(std::getenv("TISSUE_FORCE_NO_EGL"),
                                              std::getenv("TISSUE_GL_API"),
                                              std::getenv("TISSUE_SHADER_DIR"));
    options.log = [](stc::LogLevel, const std::string& message) {
      std::fprintf(stderr, "tissue solve: %s\n", message.c_str());
    };
    // A `follow` region's moves and a factor refactored ahead are awaited offline (no real
    // time to keep): deterministic.
    options.wait_for_region_moves = true;
    options.wait_for_factor_ahead = true;
    stc::Simulation sim(stc::load_scene(scene_path), options);
    if (!sim.backend_note().empty())
      std::fprintf(stderr, "tissue solve: %s\n", sim.backend_note().c_str());
    // A gl solve finished on the cpu says so once per distinct reason (not once per step).
    std::string last_fallback;
    const auto report_fallback = [&last_fallback](const stc::StepStats& s, const char* when) {
      if (s.fallback_reason.empty() || s.fallback_reason == last_fallback) return;
      std::fprintf(stderr, "tissue solve: %s: %s\n", when, s.fallback_reason.c_str());
      last_fallback = s.fallback_reason;
    };
    report_fallback(sim.last_stats(), "initial equilibrium");
    // Step at the trajectory's poses (the scene's times), then once more without the
    // scalpel: the final static equilibrium.
    for (const stc::BladePose& pose : sim.scene().trajectory) {
      const stc::StepStats s = sim.step(pose);
      char when[32];
      std::snprintf(when, sizeof when, "t=%.3f", pose.t);
      report_fallback(s, when);
      if (s.reached_interface && !s.region_moving)
        std::fprintf(stderr,
                     "tissue solve: t=%.3f: the blade reached the interface of the "
                     "condensed part; cutting stops there\n",
                     pose.t);
    }
    // step_ms times the trajectory's steps only, not the final equilibrium solve.
    const stc::StepTimes trajectory_steps = sim.step_times();
    const stc::StepStats final_step = sim.step(std::nullopt);
    report_fallback(final_step, "final solve");
    const double total_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!out.empty()) sim.write_vtk(out);
    if (!stats.empty()) sim.write_stats_json(stats, total_ms, &trajectory_steps);
    const stc::ModelCounts c = sim.counts();
    std::printf(
        "solved %s: %d nodes, %d tets, %d cuts, %ld CG iterations in all, residual %.3g, "
        "backend %s, %.1f ms\n",
        scene_path.c_str(), c.nodes, c.tets, c.cuts, c.cg_iterations_total, final_step.residual,
        (final_step.solved_by.empty() ? sim.backend() : final_step.solved_by).c_str(), total_ms);
    // docs/SCENE.md (solve contract): exit 3, after the outputs, when the final solve did not
    // converge.
    if (!final_step.converged) {
      char fallback[64];
      std::snprintf(fallback, sizeof fallback, "relative residual %.3g", final_step.residual);
      std::fprintf(
          stderr, "tissue solve: the final solve did not converge: %s\n",
          final_step.solver_message.empty() ? fallback : final_step.solver_message.c_str());
      return 3;
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tissue solve: %s\n", e.what());
    return 1;
  }
}
