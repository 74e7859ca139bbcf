// recovery/: u_N = K2_NN^-1 (f_N - K2_NI u_I) (docs/DESIGN.md section 5) through the kept
// factor equals the dense solve, for any interface displacement and a rescaled stiffness;
// and with u_I from the condensed interface equation the recovered part 2 is in equilibrium.
#include "soft_tissue_cutting/recovery/surface_recovery.hpp"

#include "common/condensation_fixture.hpp"

#include <gtest/gtest.h>

namespace stc {
namespace {

TEST(SurfaceRecovery, EqualsTheDenseSolveForAnyInterfaceDisplacement) {
  test::CondensationFixture fx;
  const CondensedPart c =
      condense_non_operation_part(fx.mesh, fx.elements, fx.partition, fx.loads, fx.fixed);
  fx.build_reference(c.interface_dofs, c.condensed_dofs);
  const Eigen::LDLT<Eigen::MatrixXd> nn(fx.K_NN);
  for (int seed = 1; seed <= 3; ++seed) {
    std::srand(static_cast<unsigned>(seed));
    const Vector u_i = 1e-3 * Vector::Random(c.interface_dofs.rows());
    for (double scale : {1.0, 2.5}) {
      // The part's stiffness is scale * K2: u_N = K2_NN^-1 (f_N / scale - K2_NI u_I).
      const Vector expected = nn.solve(fx.f_N / scale - fx.K_IN.transpose() * u_i);
      const Vector got = recover_condensed(c, u_i, scale);
      ASSERT_EQ(got.size(), expected.size());
      EXPECT_LT((got - expected).norm(), 1e-10 * expected.norm())
          << "seed " << seed << " scale " << scale;
    }
  }
}

TEST(SurfaceRecovery, RecoveredPartTwoIsInEquilibriumWithTheInterface) {
  test::CondensationFixture fx;
  const CondensedPart c =
      condense_non_operation_part(fx.mesh, fx.elements, fx.partition, fx.loads, fx.fixed);
  fx.build_reference(c.interface_dofs, c.condensed_dofs);
  // Clamp the operation part away (u_O = 0 is not needed: part 2 alone) and load part 2 at
  // the interface with its own forces: K0 u_I = f_I - g0 (docs/DESIGN.md section 4).
  const Vector u_i = c.K0.ldlt().solve(fx.f_I - c.g0);
  const Vector u_n = recover_condensed(c, u_i);
  // The whole part-2 system [K_II K_IN; K_NI K_NN] [u_I; u_N] = [f_I; f_N] then holds.
  const Vector r_i = fx.K_II * u_i + fx.K_IN * u_n - fx.f_I;
  const Vector r_n = fx.K_IN.transpose() * u_i + fx.K_NN * u_n - fx.f_N;
  EXPECT_LT(r_i.norm(), 1e-9 * fx.f_I.norm()) << r_i.norm();
  EXPECT_LT(r_n.norm(), 1e-9 * fx.f_N.norm()) << r_n.norm();
  EXPECT_GT(u_n.cwiseAbs().maxCoeff(), 1e-7);  // it moved (a load that does nothing proves nothing)
}

}  // namespace
}  // namespace stc
