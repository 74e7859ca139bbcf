// The CPU projected Jacobi-CG of solve/linear_solver.hpp against the direct CHOLMOD solve.
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

namespace stc {
namespace {

TEST(FemCgSolver, MatchesDirectSolveOnThigh) {
  const FullModel m = assemble_full_model(make_thigh_scene());
  auto cg = make_cpu_solver();
  EXPECT_EQ(cg->backend(), "cpu");
  cg->set_matrix(m.K);
  Vector x = Vector::Zero(m.K.rows());
  const CgResult r = cg->solve(m.f, x, {}, CgSettings{1e-13, 10000});
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.residual, 1e-13);
  EXPECT_NEAR(r.residual, (m.f - m.K * x).norm() / m.f.norm(), 1e-15);
  Vector xd;
  solve_direct(m.K, m.f, xd);
  EXPECT_LE((x - xd).norm(), 1e-10 * xd.norm());
  // Warm start from the solution: no iteration needed.
  const CgResult again = cg->solve(m.f, x, {}, CgSettings{1e-10, 10000});
  EXPECT_EQ(again.iterations, 0);
}

TEST(FemCgSolver, ProjectedConstrainedDofs) {
  const FullModel m = assemble_full_model(make_thigh_scene());
  const int n = static_cast<int>(m.K.rows());
  std::vector<std::uint8_t> constrained(static_cast<size_t>(n), 0);
  Vector x = Vector::Zero(n);
  for (int i = 0; i < n; i += 37) {
    constrained[static_cast<size_t>(i)] = 1;
    x[i] = 1e-3 * std::sin(i);
  }
  const Vector held = x;
  auto cg = make_cpu_solver();
  cg->set_matrix(m.K);
  const Vector b = Vector::Zero(n);  // only the imposed values drive it
  const CgResult r = cg->solve(b, x, constrained, CgSettings{1e-13, 10000});
  EXPECT_TRUE(r.converged);
  Vector xd = held;
  solve_direct(m.K, b, xd, constrained);
  for (int i = 0; i < n; ++i) {
    if (constrained[static_cast<size_t>(i)]) {
      EXPECT_EQ(x[i], held[i]);
    }
  }
  EXPECT_LE((x - xd).norm(), 1e-10 * xd.norm());
}

}  // namespace
}  // namespace stc
