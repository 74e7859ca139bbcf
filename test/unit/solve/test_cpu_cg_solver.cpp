// The CPU projected Jacobi-CG of solve/linear_solver.hpp against the direct CHOLMOD solve, and
// its factor refactored ahead on a second thread.
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

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

// A matrix shaped like the organ liver's hybrid matrix, whose refactorization is dear enough
// to be refactored ahead on a second thread (cpu_cg_solver.cpp, kPrefactorShare): a dense
// leading block of `dense` rows (the interface, K0) coupled to one face of a g^3 grid (the
// operation part, one DOF per node). Diagonally dominant, so SPD.
SparseMatrix interface_heavy_matrix(int dense, int g) {
  const int n = dense + g * g * g;
  const auto node = [&](int x, int y, int z) { return dense + x + g * (y + g * z); };
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < dense; ++i) {
    t.emplace_back(i, i, 3.0);
    for (int j = 0; j < dense; ++j)
      if (j != i) t.emplace_back(i, j, 0.1 / dense);
    const int face = node(i % g, (i / g) % g, 0);
    t.emplace_back(i, face, -0.2);
    t.emplace_back(face, i, -0.2);
  }
  for (int z = 0; z < g; ++z)
    for (int y = 0; y < g; ++y)
      for (int x = 0; x < g; ++x) {
        const int r = node(x, y, z);
        t.emplace_back(r, r, 8.0);
        if (x + 1 < g) t.emplace_back(r, node(x + 1, y, z), -1.0);
        if (x > 0) t.emplace_back(r, node(x - 1, y, z), -1.0);
        if (y + 1 < g) t.emplace_back(r, node(x, y + 1, z), -1.0);
        if (y > 0) t.emplace_back(r, node(x, y - 1, z), -1.0);
        if (z + 1 < g) t.emplace_back(r, node(x, y, z + 1), -1.0);
        if (z > 0) t.emplace_back(r, node(x, y, z - 1), -1.0);
      }
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  a.makeCompressed();
  return a;
}

// A cut walking through the grid: each change halves the couplings of one node with its
// neighbours and appends DOFs coupled to it (a cut's new nodes, which join the frame), and
// names the rows it changed; three changes then bump rows far from the walk. Returns each
// step's solution; checks every solve is the direct step (one iteration: the factor is exactly the
// matrix's) to 1e-10 against the matrix.
std::vector<Vector> solves_along_a_walk(bool await_factor_ahead, int* taken_ahead) {
  constexpr int kDense = 700, kGrid = 12, kNewDofs = 60;
  SparseMatrix a = interface_heavy_matrix(kDense, kGrid);
  auto solver = make_cpu_solver();
  solver->set_matrix(a);
  std::vector<Vector> out;
  for (int step = 0; step < 30; ++step) {
    const int n = static_cast<int>(a.rows());
    const int x = 1 + step % 10, y = 3 + 3 * (step / 10), z = 6;
    const int c = kDense + x + kGrid * (y + kGrid * z);
    std::vector<int> changed = {c};
    std::vector<Eigen::Triplet<double>> t;
    for (int k = 0; k < a.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(a, k); it; ++it) {
        const bool coupling = (it.row() == c) != (it.col() == c) && it.row() >= kDense &&
                              it.col() >= kDense && it.row() < kDense + kGrid * kGrid * kGrid &&
                              it.col() < kDense + kGrid * kGrid * kGrid;
        t.emplace_back(it.row(), it.col(), coupling ? 0.5 * it.value() : it.value());
        if (coupling && it.row() == c) changed.push_back(static_cast<int>(it.col()));
      }
    for (int k = 0; k < kNewDofs; ++k) {
      t.emplace_back(n + k, n + k, 8.0);
      t.emplace_back(n + k, c, -0.1);
      t.emplace_back(c, n + k, -0.1);
    }
    t.emplace_back(c, c, 0.1 * kNewDofs + 0.5);  // c stays diagonally dominant
    a.resize(n + kNewDofs, n + kNewDofs);
    a.setFromTriplets(t.begin(), t.end());
    a.makeCompressed();
    LinearSolver::History history;
    history.kept_rows = n;
    history.interface_rows = kDense;
    history.changed_rows = &changed;
    history.await_factor_ahead = await_factor_ahead;
    solver->set_matrix(a, {}, history);
    // Changes right after, far from the walk, one row each: a factor refactored ahead since
    // the walk's change is still being made, and must take all of them when it is taken.
    for (int far_x : {2, 5, 8}) {
      const int far = kDense + far_x + kGrid * (5 + kGrid * 1);
      a.coeffRef(far, far) += 1e-3;
      std::vector<int> far_rows = {far};
      history.kept_rows = static_cast<int>(a.rows());
      history.changed_rows = &far_rows;
      solver->set_matrix(a, {}, history);
    }
    Vector b(a.rows());
    for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = std::sin(1.0 + static_cast<double>(i));
    Vector u = Vector::Zero(a.rows());
    const CgResult r = solver->solve(b, u, {}, CgSettings{1e-10, 100});
    EXPECT_TRUE(r.converged) << "step " << step;
    EXPECT_EQ(r.iterations, 1) << "step " << step << ": not the direct step";
    EXPECT_LE((b - a * u).norm() / b.norm(), 1e-10) << "step " << step;
    out.push_back(u);
  }
  *taken_ahead = solver->factors_taken_ahead();
  return out;
}

// The factor refactored ahead (docs/DESIGN.md section 6.2): offline (await) it is taken at the
// next change, so two runs solve with the same factors bit for bit; online it is taken once
// ready, with every change made meanwhile, and the solutions differ by rounding only. The
// thread factors its own copy of the matrix, which the solver changes meanwhile: a factor of
// the changed arrays would not solve in one step.
TEST(FemCgSolver, TakesTheFactorRefactoredAheadAwaitedOrWhenReady) {
  int ahead_offline = 0, ahead_again = 0, ahead_online = 0;
  const std::vector<Vector> offline = solves_along_a_walk(true, &ahead_offline);
  const std::vector<Vector> again = solves_along_a_walk(true, &ahead_again);
  const std::vector<Vector> online = solves_along_a_walk(false, &ahead_online);
  EXPECT_GE(ahead_offline, 2) << "the walk should fill frames and refactor them ahead";
  EXPECT_EQ(ahead_again, ahead_offline);
  EXPECT_GE(ahead_online, 1);
  std::printf("factors taken ahead: offline %d, online %d\n", ahead_offline, ahead_online);
  for (size_t k = 0; k < offline.size(); ++k) {
    EXPECT_TRUE(offline[k] == again[k]) << "step " << k << ": offline runs differ";
    EXPECT_LE((online[k] - offline[k]).norm(), 1e-9 * offline[k].norm()) << "step " << k;
  }
}

}  // namespace
}  // namespace stc
