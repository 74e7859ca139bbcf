// condensation/: K0 and g0 of docs/DESIGN.md section 4 equal the dense Schur complement of
// the part-2 stiffness computed here with Eigen's dense LDLT, to rounding.
#include "soft_tissue_cutting/condensation/condensed_part.hpp"

#include "common/condensation_fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace stc {
namespace {

TEST(CondensedPart, K0AndG0EqualTheDenseSchurComplement) {
  test::CondensationFixture fx;
  const CondensedPart c =
      condense_non_operation_part(fx.mesh, fx.elements, fx.partition, fx.loads, fx.fixed);
  fx.build_reference(c.interface_dofs, c.condensed_dofs);
  ASSERT_GT(c.interface_dofs.rows(), 30);
  ASSERT_GT(c.condensed_dofs.rows(), 100);
  // Fixed DOFs are eliminated: none of them is a row.
  for (int dof : c.interface_dofs.global_of) EXPECT_FALSE(fx.fixed[static_cast<size_t>(dof / 3)]);
  for (int dof : c.condensed_dofs.global_of) EXPECT_FALSE(fx.fixed[static_cast<size_t>(dof / 3)]);

  const Eigen::LDLT<Eigen::MatrixXd> nn(fx.K_NN);
  const Eigen::MatrixXd k0 = fx.K_II - fx.K_IN * nn.solve(fx.K_IN.transpose());
  const Vector g0 = fx.K_IN * nn.solve(fx.f_N);
  const double k0_err = (c.K0 - k0).norm() / k0.norm();
  const double g0_err = (c.g0 - g0).norm() / g0.norm();
  EXPECT_LT(k0_err, 1e-10) << "K0 relative error " << k0_err;
  EXPECT_LT(g0_err, 1e-10) << "g0 relative error " << g0_err;
  EXPECT_LT((c.K0 - c.K0.transpose()).norm(), 1e-14 * c.K0.norm());
  // K0 is the stiffness part 2 offers at the interface: positive definite (part 2 is fixed at
  // the bottom), and softer than K_II alone (the Schur complement subtracts a PSD term).
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(c.K0);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
  const Vector softening = (fx.K_II - c.K0).diagonal();
  EXPECT_GE(softening.minCoeff(), -1e-9 * k0.norm());
  EXPECT_GT(softening.maxCoeff(), 1e-3 * fx.K_II.diagonal().maxCoeff());
  // The kept blocks for the recovery are the reference ones.
  EXPECT_LT((Eigen::MatrixXd(c.K2_NI) - fx.K_IN.transpose()).norm(), 1e-12 * fx.K_NN.norm());
  EXPECT_LT((c.f_N - fx.f_N).norm(), 1e-15);
}

TEST(CondensedPart, AFreeFloatingPartTwoIsRefusedWithAMessage) {
  test::CondensationFixture fx;
  std::fill(fx.fixed.begin(), fx.fixed.end(), 0);  // nothing fixed: K2_NN has rigid modes
  OperationRegion none;
  none.kind = OperationRegion::Kind::kNone;  // no interface either: part 2 floats
  fx.partition = partition_mesh(fx.mesh, none);
  try {
    condense_non_operation_part(fx.mesh, fx.elements, fx.partition, fx.loads, fx.fixed);
    FAIL() << "a singular K2_NN was condensed";
  } catch (const std::runtime_error& e) {
    EXPECT_FALSE(std::string(e.what()).empty());
  }
}

}  // namespace
}  // namespace stc
