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

// A system that is not positive definite (eigenvalues 3 and -1; the diagonal is 1, so Jacobi
// is the identity): from x = 0 the first CG step lands on (1, 0), whose residual is twice the
// start's, and the next direction has p'Ap < 0. The solver must report the failure and hand
// back the better of the two (the start), never the worse one.
TEST(FemCgSolver, NeverReturnsAnIterateWorseThanItsStart) {
  SparseMatrix a(2, 2);
  a.insert(0, 0) = 1;
  a.insert(0, 1) = 2;
  a.insert(1, 0) = 2;
  a.insert(1, 1) = 1;
  a.makeCompressed();
  const Vector b = Vector::Unit(2, 0);
  auto cg = make_cpu_solver(CgPreconditioner::kJacobi);
  cg->set_matrix(a);
  Vector x = Vector::Zero(2);
  const CgResult r = cg->solve(b, x, {}, CgSettings{1e-10, 100});
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(x, Vector::Zero(2)) << "the worse iterate " << x.transpose() << " was returned";
  EXPECT_DOUBLE_EQ(r.residual, 1.0);  // the start's, not the last iterate's 2
  EXPECT_NE(r.message.find("the one before this pass is kept"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace stc
