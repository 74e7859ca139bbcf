// The two preconditioners of the CPU projected CG (solve/linear_solver.hpp) on the thigh's
// hybrid system (docs/DESIGN.md eq. (10)): same solution as the direct CHOLMOD solve, with
// and without constrained (contact) DOFs; the Cholesky preconditioner converges in about
// #constrained iterations where Jacobi needs hundreds; matrices that cannot be factored fall
// back observably instead of crashing.
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace stc {
namespace {

const HybridModel& thigh_model() {
  static const HybridModel h(make_thigh_scene());
  return h;
}

// The hybrid rows of the first loaded (contact) node and of a few more O nodes: the contact
// patch of a scalpel step, ~a dozen DOFs.
std::vector<int> contact_rows(const HybridModel& h) {
  const Scene s = make_thigh_scene();
  std::vector<int> nodes = s.loads.at(0).where.nodes;
  for (int i : h.partition().operation) {
    if (nodes.size() >= 4) break;
    nodes.push_back(i);
  }
  nodes.resize(std::min<size_t>(nodes.size(), 4));
  std::vector<int> rows;
  for (int node : nodes)
    for (int c = 0; c < 3; ++c) {
      const int r = h.hybrid_dofs().row_of[static_cast<size_t>(3 * node + c)];
      if (r >= 0) rows.push_back(r);
    }
  return rows;
}

struct Named {
  CgPreconditioner kind;
  const char* name;
};
const Named kBoth[] = {{CgPreconditioner::kJacobi, "jacobi"},
                       {CgPreconditioner::kCholesky, "cholesky"}};

TEST(FemCgPreconditioner, DefaultIsCholesky) {
  auto cg = make_cpu_solver();
  cg->set_matrix(thigh_model().hybrid_matrix());
  EXPECT_EQ(cg->preconditioner(), "cholesky");
  EXPECT_GT(cg->setup_ms(), 0);
  EXPECT_EQ(thigh_model().solver().preconditioner(), "cholesky");
}

TEST(FemCgPreconditioner, MatchesDirectSolveOnThighHybrid) {
  const SparseMatrix& a = thigh_model().hybrid_matrix();
  const Vector& b = thigh_model().hybrid_rhs();
  Vector xd;
  solve_direct(a, b, xd);
  for (const Named& p : kBoth) {
    SCOPED_TRACE(p.name);
    auto cg = make_cpu_solver(p.kind);
    cg->set_matrix(a);
    EXPECT_EQ(cg->preconditioner(), p.name);
    Vector x = Vector::Zero(a.rows());
    const CgResult r = cg->solve(b, x, {}, CgSettings{1e-13, 20000});
    EXPECT_TRUE(r.converged);
    EXPECT_LE(r.residual, 1e-13);
    EXPECT_LE((x - xd).norm(), 1e-9 * xd.norm());
    if (p.kind == CgPreconditioner::kCholesky) {
      EXPECT_LE(r.iterations, 3);
    }
  }
}

TEST(FemCgPreconditioner, MatchesDirectSolveWithConstrainedDofs) {
  const SparseMatrix& a = thigh_model().hybrid_matrix();
  const Vector& b = thigh_model().hybrid_rhs();
  const int n = static_cast<int>(a.rows());
  std::vector<std::uint8_t> constrained(static_cast<size_t>(n), 0);
  Vector x0 = Vector::Zero(n);
  for (int r : contact_rows(thigh_model())) {
    constrained[static_cast<size_t>(r)] = 1;
    x0[r] = -2e-3 * std::cos(r);
  }
  Vector xd = x0;
  solve_direct(a, b, xd, constrained);
  for (const Named& p : kBoth) {
    SCOPED_TRACE(p.name);
    auto cg = make_cpu_solver(p.kind);
    cg->set_matrix(a);
    Vector x = x0;
    const CgResult r = cg->solve(b, x, constrained, CgSettings{1e-13, 20000});
    EXPECT_TRUE(r.converged);
    for (int i = 0; i < n; ++i) {
      if (constrained[static_cast<size_t>(i)]) {
        EXPECT_EQ(x[i], x0[i]);
      }
    }
    EXPECT_LE((x - xd).norm(), 1e-9 * xd.norm());
  }
}

// A scalpel step: from equilibrium, the contact patch is pushed further; warm-started solve at
// the scene's tolerance. Rank argument: <= #constrained + 1 Cholesky-PCG iterations.
TEST(FemCgPreconditioner, CholeskyNeedsFarFewerIterationsUnderContact) {
  const SparseMatrix& a = thigh_model().hybrid_matrix();
  const Vector& b = thigh_model().hybrid_rhs();
  const int n = static_cast<int>(a.rows());
  const std::vector<int> rows = contact_rows(thigh_model());
  ASSERT_GE(rows.size(), 9u);
  std::vector<std::uint8_t> constrained(static_cast<size_t>(n), 0);
  for (int r : rows) constrained[static_cast<size_t>(r)] = 1;
  Vector equilibrium;
  solve_direct(a, b, equilibrium);
  int iterations[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    auto cg = make_cpu_solver(kBoth[k].kind);
    cg->set_matrix(a);
    Vector x = equilibrium;
    for (int r : rows) x[r] -= 1e-3;
    const CgResult res = cg->solve(b, x, constrained, CgSettings{1e-10, 20000});
    EXPECT_TRUE(res.converged);
    iterations[k] = res.iterations;
    // Nothing moved: warm start is already the solution.
    EXPECT_EQ(cg->solve(b, x, constrained, CgSettings{1e-10, 20000}).iterations, 0);
  }
  EXPECT_GT(iterations[0], 100) << "jacobi";
  EXPECT_LT(iterations[1], 20) << "cholesky";
  EXPECT_LE(iterations[1], static_cast<int>(rows.size()) + 1);
}

// A held free piece (simulation.cpp): a block of A with no anchor, all of its DOFs
// constrained. The unshifted factorization fails; the shifted one preconditions the rest.
TEST(FemCgPreconditioner, HeldFreePieceUsesShiftedCholesky) {
  const SparseMatrix& k = thigh_model().hybrid_matrix();
  const int n = static_cast<int>(k.rows()), m = 12;
  std::vector<Eigen::Triplet<double, int>> t;
  for (int r = 0; r < n; ++r)
    for (SparseMatrix::InnerIterator it(k, r); it; ++it) t.emplace_back(r, it.col(), it.value());
  const double s = k.diagonal().mean();
  for (int i = 0; i + 1 < m; ++i) {  // a path-graph Laplacian: singular (constant mode)
    const int p = n + i, q = n + i + 1;
    t.emplace_back(p, p, s), t.emplace_back(q, q, s);
    t.emplace_back(p, q, -s), t.emplace_back(q, p, -s);
  }
  SparseMatrix a(n + m, n + m);
  a.setFromTriplets(t.begin(), t.end());
  Vector b = Vector::Zero(n + m);
  b.head(n) = thigh_model().hybrid_rhs();
  std::vector<std::uint8_t> constrained(static_cast<size_t>(n + m), 0);
  Vector x0 = Vector::Zero(n + m);
  for (int i = n; i < n + m; ++i) constrained[static_cast<size_t>(i)] = 1, x0[i] = 1e-3;
  for (int r : contact_rows(thigh_model())) constrained[static_cast<size_t>(r)] = 1, x0[r] = -1e-3;
  Vector xd = x0;
  solve_direct(a, b, xd, constrained);

  auto cg = make_cpu_solver(CgPreconditioner::kCholesky);
  cg->set_matrix(a);
  EXPECT_EQ(cg->preconditioner(), "cholesky (shifted)");
  Vector x = x0;
  const CgResult r = cg->solve(b, x, constrained, CgSettings{1e-12, 20000});
  EXPECT_TRUE(r.converged);
  EXPECT_LT(r.iterations, 25);
  EXPECT_LE((x - xd).norm(), 1e-9 * xd.norm());
}

// The same held piece, named as held (set_matrix(a, held), as the simulation does): the factor
// is of A without its DOFs, so no shift is needed. With every held DOF constrained the solve is
// the direct step on the kept DOFs (capacitance on the contact DOFs, docs/DESIGN.md eqs.
// (24)-(25)): one iteration. With a held DOF left free, projected CG preconditioned by that
// factor takes about one iteration more than the contact DOFs (docs/DESIGN.md eq. (16)).
TEST(FemCgPreconditioner, NamedHeldPieceIsLeftOutOfTheFactor) {
  const SparseMatrix& k = thigh_model().hybrid_matrix();
  const int n = static_cast<int>(k.rows()), m = 12;
  std::vector<Eigen::Triplet<double, int>> t;
  for (int r = 0; r < n; ++r)
    for (SparseMatrix::InnerIterator it(k, r); it; ++it) t.emplace_back(r, it.col(), it.value());
  const double s = k.diagonal().mean();
  for (int i = 0; i + 1 < m; ++i) {  // a path-graph Laplacian: singular (constant mode)
    const int p = n + i, q = n + i + 1;
    t.emplace_back(p, p, s), t.emplace_back(q, q, s);
    t.emplace_back(p, q, -s), t.emplace_back(q, p, -s);
  }
  SparseMatrix a(n + m, n + m);
  a.setFromTriplets(t.begin(), t.end());
  Vector b = Vector::Zero(n + m);
  b.head(n) = thigh_model().hybrid_rhs();
  std::vector<std::uint8_t> constrained(static_cast<size_t>(n + m), 0), held = constrained;
  Vector x0 = Vector::Zero(n + m);
  for (int i = n; i < n + m; ++i) constrained[static_cast<size_t>(i)] = held[i] = 1, x0[i] = 1e-3;
  const std::vector<int> contact = contact_rows(thigh_model());
  for (int r : contact) constrained[static_cast<size_t>(r)] = 1, x0[r] = -1e-3;
  Vector xd = x0;
  solve_direct(a, b, xd, constrained);

  auto cg = make_cpu_solver(CgPreconditioner::kCholesky);
  cg->set_matrix(a, held);
  EXPECT_EQ(cg->preconditioner(), "cholesky");
  Vector x = x0;
  const CgResult r = cg->solve(b, x, constrained, CgSettings{1e-12, 20000});
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 1) << "the direct step on the kept DOFs";
  EXPECT_LE((x - xd).norm(), 1e-9 * xd.norm());
  for (int i = n; i < n + m; ++i) EXPECT_EQ(x[i], x0[i]);  // held values exactly
  // A held DOF this solve leaves free: projected CG. Exact arithmetic: #constrained kept + 1;
  // measured 14 for 12 contact DOFs at 1e-12 (round-off).
  std::vector<std::uint8_t> one_free = constrained;
  one_free[static_cast<size_t>(n + m - 1)] = 0;
  Vector xf = x0;
  solve_direct(a, b, xf, one_free);
  x = x0;
  const CgResult rf = cg->solve(b, x, one_free, CgSettings{1e-12, 20000});
  EXPECT_TRUE(rf.converged);
  EXPECT_GT(rf.iterations, 1);
  EXPECT_LE(rf.iterations, static_cast<int>(contact.size()) + 4) << rf.iterations;
  EXPECT_LE((x - xf).norm(), 1e-9 * xf.norm());
  EXPECT_THROW(cg->set_matrix(a, std::vector<std::uint8_t>(3, 1)), std::invalid_argument);
}

// No SPD factor even shifted (indefinite): Jacobi for that matrix, no crash; the next SPD
// matrix is factored again.
TEST(FemCgPreconditioner, IndefiniteMatrixFallsBackToJacobi) {
  std::vector<Eigen::Triplet<double, int>> t = {
      {0, 0, 1.0}, {1, 1, 1.0}, {0, 1, 2.0}, {1, 0, 2.0}, {2, 2, 3.0}};
  SparseMatrix a(3, 3);
  a.setFromTriplets(t.begin(), t.end());
  auto cg = make_cpu_solver(CgPreconditioner::kCholesky);
  cg->set_matrix(a);
  EXPECT_EQ(cg->preconditioner(), "jacobi");
  Vector x = Vector::Zero(3);
  const Vector b = Vector::Ones(3);
  EXPECT_NO_THROW(cg->solve(b, x, {}, CgSettings{1e-10, 100}));
  // Constraining the indefinite pair leaves an SPD free block: solved exactly.
  x = Vector::Zero(3);
  const CgResult r = cg->solve(b, x, {1, 1, 0}, CgSettings{1e-10, 100});
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(x[2], 1.0 / 3.0, 1e-12);

  cg->set_matrix(thigh_model().hybrid_matrix());
  EXPECT_EQ(cg->preconditioner(), "cholesky");
}

}  // namespace
}  // namespace stc
