// The per-step shortcuts of the hybrid model stay exact (docs/DESIGN.md, per-step cost):
// an unchanged step returns the last solution without solving, and u_S, u_Q are recovered
// through the factor of K2_NN only when u_I moved, yet always equal the full model.
#include "liver_test_scene.hpp"

#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

namespace stc {
namespace {

// Max nodal error of h's displacement (every node) against the full model, relative to the
// largest reference displacement.
double error_vs_full(const HybridModel& h, const ImposedDisplacements& imposed) {
  const ElementStiffnessCache cache(h.mesh(), h.material());
  const FullModel full = assemble_full_model(h.mesh(), cache, h.loads(), h.fixed_nodes());
  Vector x = Vector::Zero(full.K.rows());
  std::vector<std::uint8_t> constrained(static_cast<size_t>(x.size()), 0);
  for (const auto& [node, d] : imposed)
    for (int c = 0; c < 3; ++c) {
      const int row = full.dofs.row_of[static_cast<size_t>(3 * node + c)];
      if (row >= 0) x[row] = d[c], constrained[static_cast<size_t>(row)] = 1;
    }
  solve_direct(full.K, full.f, x, constrained);
  Vector ref = Vector::Zero(3 * h.mesh().num_nodes());
  scatter(x, full.dofs, ref);
  const Vector& u = h.displacement();
  double scale = 0, err = 0;
  for (int n = 0; n < h.mesh().num_nodes(); ++n) {
    scale = std::max(scale, ref.segment<3>(3 * n).norm());
    err = std::max(err, (u.segment<3>(3 * n) - ref.segment<3>(3 * n)).norm());
  }
  return err / scale;
}

void check_press_idle_release(const Scene& scene, const char* name) {
  HybridModel h(scene);
  h.set_cg_settings(CgSettings{1e-13, 20000});
  ASSERT_FALSE(h.partition().interface.empty());
  ASSERT_FALSE(h.partition().surface.empty());
  const CgResult first = h.solve();
  ASSERT_TRUE(first.converged);
  EXPECT_LE(error_vs_full(h, {}), 1e-9) << name;
  const long recoveries = h.recoveries();

  // Idle: nothing changed, nothing solved, nothing recovered, the same exact answer.
  const Vector before = h.displacement();
  const CgResult idle = h.solve();
  EXPECT_EQ(idle.iterations, 0);
  EXPECT_TRUE(idle.converged);
  EXPECT_EQ(h.recoveries(), recoveries);
  EXPECT_EQ((h.displacement() - before).cwiseAbs().maxCoeff(), 0.0);

  // Press an operation node next to the interface (its move reaches u_I).
  const int node = h.partition().operation.front();
  const ImposedDisplacements press{{node, Vec3(0.002, -0.003, 0.001)}};
  const CgResult pressed = h.solve(press);
  ASSERT_TRUE(pressed.converged);
  EXPECT_GT(pressed.iterations, 0);
  EXPECT_EQ(h.recoveries(), recoveries);             // nothing asked for S or Q yet
  EXPECT_LE(error_vs_full(h, press), 1e-9) << name;  // asks: recovered once, exact
  EXPECT_EQ(h.recoveries(), recoveries + 1);
  EXPECT_EQ(h.solve(press).iterations, 0);  // the same press again: idle
  h.displacement();
  EXPECT_EQ(h.recoveries(), recoveries + 1);

  // Release: solves again, and is the unloaded equilibrium again.
  const CgResult released = h.solve();
  EXPECT_GT(released.iterations, 0);
  EXPECT_LE(error_vs_full(h, {}), 1e-9) << name;
  EXPECT_LE((h.displacement() - before).cwiseAbs().maxCoeff(), 1e-8 * before.cwiseAbs().maxCoeff())
      << name;
}

// A tighter tolerance is a change: the same step is solved again, to the new tolerance (plain
// Jacobi CG, so the loose solve really is loose).
TEST(HybridLazyRecovery, NewToleranceSolvesAgain) {
  HybridModel h(make_thigh_scene(), make_cpu_solver(CgPreconditioner::kJacobi));
  h.set_cg_settings(CgSettings{1e-3, 20000});
  const CgResult loose = h.solve();
  ASSERT_TRUE(loose.converged);
  EXPECT_GT(loose.residual, 1e-9);
  h.set_cg_settings(CgSettings{1e-12, 20000});
  const CgResult tight = h.solve();
  EXPECT_GT(tight.iterations, 0);
  EXPECT_LE(tight.residual, 1e-12);
  EXPECT_LE(error_vs_full(h, {}), 1e-9);
}

TEST(HybridLazyRecovery, ThighPressIdleRelease) {
  Scene s = make_thigh_scene();
  s.gravity = Vec3(0, -9.81, 0);
  check_press_idle_release(s, "thigh");
}

TEST(HybridLazyRecovery, LiverPressIdleRelease) {
  check_press_idle_release(testing_scenes::liver_scene("sofa_liver2.msh", true, 3, 0.25), "liver2");
}

}  // namespace
}  // namespace stc
