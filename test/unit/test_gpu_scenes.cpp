// Every shipped scene on the "gl" backend against "cpu": whatever config/scenes/*.yaml holds
// (the directory is listed at run time, so scenes added later are covered), plus the built-in
// thigh through its pressing-and-cutting trajectory. The gl solve (float32 CG on Mesa
// llvmpipe + double refinement) must converge to the scene's tolerance by itself (no CPU
// fallback) and give the cpu's displacements to 1e-6 relative, interior nodes included.
#include "soft_tissue_cutting/gpu/gl_solver.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace stc {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> shipped_scenes() {
  std::vector<std::string> out;
  const fs::path dir = fs::path(TISSUE_TEST_DATA_DIR) / ".." / ".." / "config" / "scenes";
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".yaml") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  out.push_back("thigh");  // the built-in scene: presses, cuts twice (111 tets split)
  return out;
}

double relative(const Vector& a, const Vector& ref) {
  const double n = ref.norm();
  return n > 0 ? (a - ref).norm() / n : a.norm();
}

struct Outcome {
  Vector u;  // every node, interior ones of the condensed part recovered
  StepStats last;
  ModelCounts counts;
};

// Plays the scene as `tissue solve` does: trajectory, then the final equilibrium.
Outcome play(const Scene& scene, const std::string& backend) {
  SimulationOptions options;
  options.backend = backend;
  Simulation sim(scene, options);
  EXPECT_EQ(sim.backend(), backend) << sim.backend_note();
  for (const BladePose& pose : scene.trajectory) {
    const StepStats s = sim.step(pose);
    EXPECT_TRUE(s.converged) << backend << " t=" << pose.t << ": " << s.solver_message;
    EXPECT_EQ(s.solved_by, backend) << s.fallback_reason;
  }
  Outcome o;
  o.last = sim.step(std::nullopt);
  o.u = sim.full_displacement();
  o.counts = sim.counts();
  return o;
}

class GlScenes : public ::testing::TestWithParam<std::string> {};

TEST_P(GlScenes, GlMatchesCpuAndConvergesWithoutFallback) {
  const auto t0 = std::chrono::steady_clock::now();
  Scene scene = load_scene(GetParam());
  const double tolerance = 1e-6;
  if (scene.trajectory.empty()) {
    // An unloaded static scene (a mesh to cut interactively) would compare zero with zero:
    // load it with gravity so both backends have something to solve on its mesh.
    if (scene.loads.empty() && scene.gravity.isZero()) scene.gravity = Vec3(0, 0, -9.81);
    // A static scene is its initial equilibrium: condense once, solve on both backends
    // (the 55k-tet liver's condensation is the expensive part; no need to do it twice).
    HybridModel model(scene, make_cpu_solver());
    const CgResult cpu = model.solve();
    ASSERT_TRUE(cpu.converged) << cpu.message;
    model.recover_interior();
    const Vector u_cpu = model.displacement();
    std::string why;
    auto gl = make_gl_solver(&why);
    ASSERT_TRUE(gl) << "EGL/GL must work on llvmpipe here: " << why;
    model.set_solver(std::move(gl));
    model.reset_displacement();  // a cold start, as the gl run of `tissue solve` has
    const CgResult r = model.solve();
    model.recover_interior();
    const double err = relative(model.displacement(), u_cpu);
    std::printf(
        "%s: %d DOF, gl %d iterations, residual %.2e (cpu %.2e), |u_gl - u_cpu| / "
        "|u_cpu| = %.2e, %.1f s\n",
        GetParam().c_str(), model.counts().dof_operation, r.iterations, r.residual, cpu.residual,
        err, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    EXPECT_TRUE(r.converged) << r.message;
    EXPECT_LE(r.residual, scene.solver.tolerance);
    EXPECT_TRUE(r.solved_by == "gl" || model.counts().dof_operation == 0) << r.fallback_reason;
    EXPECT_TRUE(r.fallback_reason.empty()) << r.fallback_reason;
    EXPECT_LE(err, tolerance);
    return;
  }
  // A trajectory (contact, pressure-triggered cuts): play it on both and compare the end.
  const Outcome cpu = play(scene, "cpu");
  const Outcome gl = play(scene, "gl");
  ASSERT_EQ(gl.counts.cuts, cpu.counts.cuts);
  ASSERT_EQ(gl.counts.tets, cpu.counts.tets);
  ASSERT_EQ(gl.u.size(), cpu.u.size());
  const double err = relative(gl.u, cpu.u);
  std::printf(
      "%s: %d cuts, %d tets split, gl %ld iterations in all, final residual %.2e, "
      "|u_gl - u_cpu| / |u_cpu| = %.2e, %.1f s\n",
      GetParam().c_str(), gl.counts.cuts, gl.counts.tets_split, gl.counts.cg_iterations_total,
      gl.last.residual, err,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  EXPECT_TRUE(gl.last.converged) << gl.last.solver_message;
  EXPECT_EQ(gl.counts.solver_fallbacks, 0);
  EXPECT_LE(err, tolerance);
}

INSTANTIATE_TEST_SUITE_P(Shipped, GlScenes, ::testing::ValuesIn(shipped_scenes()),
                         [](const ::testing::TestParamInfo<std::string>& i) {
                           std::string name = fs::path(i.param).stem().string();
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace stc
