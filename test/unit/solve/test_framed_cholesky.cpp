// The framed Cholesky factor (docs/DESIGN.md section 6.2, eqs. (26)-(27),
// solve/framed_cholesky.hpp): after a cut that changed nothing outside the frame, refactoring
// the frame's dense Schur complement alone solves the new hybrid matrix as exactly as a fresh
// factorization, on the real matrices of cut strokes (the thigh, a sagging TetGen liver); any
// change outside the frame, a new DOF coupled outside it, or a frame that is no longer
// positive definite is refused and leaves the factor as it was; the CPU solver takes most cuts
// of a stroke through the frame.
#include "soft_tissue_cutting/cutting/blade_path.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/solve/framed_cholesky.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace stc {
namespace {

double relative(const Eigen::MatrixXd& x, const Eigen::MatrixXd& ref) {
  return (x - ref).norm() / ref.norm();
}

// A right-hand side with every row non-zero, and a second column.
Eigen::MatrixXd two_columns(const Vector& b) {
  Eigen::MatrixXd out(b.size(), 2);
  out.col(0) = b;
  for (Eigen::Index i = 0; i < b.size(); ++i) out(i, 1) = std::sin(1.0 + static_cast<double>(i));
  return out;
}

// The built-in thigh with its scripted stroke in 1 mm poses (as the bench steps it).
Scene thigh_stroke() {
  Scene thigh = make_thigh_scene();
  thigh.trajectory = resample_blade_path(thigh.trajectory, thigh.scalpel.blade_length, 1e-3);
  return thigh;
}

Scene tetgen_liver() {  // config/scenes/liver_cut.yaml: a TetGen liver sagging under gravity
  return load_scene(std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/liver_cut.yaml");
}

struct StrokeCounts {
  int cuts = 0, updates = 0, checked = 0;
};

// Plays the scene's trajectory; at every cutting step the hybrid matrix is taken by the framed
// factor the way the CPU solver does (update, else refactor with a frame around what changed)
// and both solves are compared with a fresh factorization of the same matrix.
StrokeCounts framed_along_stroke(const Scene& scene, const std::string& what) {
  Simulation sim(scene);
  const int dense = 3 * static_cast<int>(sim.model().partition().interface.size());
  std::unique_ptr<FramedCholesky> factor;
  SparseMatrix previous = sim.model().hybrid_matrix();
  StrokeCounts n;
  for (const BladePose& pose : scene.trajectory) {
    const StepStats s = sim.step(pose);
    if (!s.cutting) continue;
    ++n.cuts;
    const SparseMatrix& a = sim.model().hybrid_matrix();
    // A held free piece may leave A singular (its factor is of D, the held DOFs decoupled,
    // cpu_cg_solver.cpp): those steps are the solver's test below.
    const auto& held = sim.model().held_nodes();
    if (std::find(held.begin(), held.end(), 1) != held.end()) {
      factor.reset();
      previous = a;
      continue;
    }
    if (factor && factor->update(a)) {
      ++n.updates;
    } else {
      factor = std::make_unique<FramedCholesky>(
          a, FramedCholesky::frame_around_changes(previous, a, dense, 1));
    }
    previous = a;
    EXPECT_EQ(factor->rows(), a.rows()) << what;
    const Eigen::MatrixXd b = two_columns(sim.model().hybrid_rhs());
    const SparseCholesky fresh(a, CholeskyMethod::kSupernodal, CholeskyOrdering::kAmd);
    const Eigen::MatrixXd ref = fresh.solve(b);
    const Eigen::MatrixXd x = factor->solve(b);
    EXPECT_LE(relative(x, ref), 1e-11) << what << ", cut " << n.cuts << " (frame "
                                       << factor->frame_size() << " of " << a.rows() << ")";
    EXPECT_LE(relative(factor->solve(Vector(b.col(0))), ref.col(0)), 1e-11) << what;
    ++n.checked;
  }
  std::printf("[ framed   ] %s: %d cuts, %d through the frame, %d checked\n", what.c_str(), n.cuts,
              n.updates, n.checked);
  return n;
}

TEST(FramedCholesky, CutStrokeEqualsFreshFactorOnThigh) {
  const StrokeCounts n = framed_along_stroke(thigh_stroke(), "thigh");
  EXPECT_GE(n.cuts, 10);
  EXPECT_EQ(n.checked, n.cuts);
  // Measured: 18 of 24 cuts inside the frame of the cut before.
  EXPECT_GE(2 * n.updates, n.cuts) << n.updates << " of " << n.cuts << " cuts updated the frame";
}

TEST(FramedCholesky, CutStrokeEqualsFreshFactorOnTetgenLiver) {
  const StrokeCounts n = framed_along_stroke(tetgen_liver(), "TetGen liver");
  EXPECT_GE(n.cuts, 10);
  EXPECT_GE(2 * n.updates, n.cuts) << n.updates << " of " << n.cuts << " cuts updated the frame";
}

// The thigh's hybrid matrix with a frame of the rows around one operation node.
struct Framed {
  SparseMatrix a;
  std::vector<int> frame;
  int outside = -1;  // a row outside the frame, not an interface row
  int dense = 0;     // the interface rows
};

Framed framed_matrix(const Scene& scene) {
  const HybridModel h(scene);
  Framed f;
  f.a = h.hybrid_matrix();
  const int dense = 3 * static_cast<int>(h.partition().interface.size());
  f.dense = dense;
  // Pretend the last row changed: its neighbours, one ring, are the frame.
  SparseMatrix before = f.a;
  before.coeffRef(f.a.rows() - 1, f.a.rows() - 1) *= 2;
  f.frame = FramedCholesky::frame_around_changes(before, f.a, dense, 1);
  std::vector<char> in(static_cast<size_t>(f.a.rows()), 0);
  for (int r : f.frame) in[static_cast<size_t>(r)] = 1;
  for (int r = f.a.rows() - 1; r >= dense; --r)
    if (!in[static_cast<size_t>(r)]) {
      f.outside = r;
      break;
    }
  return f;
}

Framed thigh_matrix() { return framed_matrix(make_thigh_scene()); }

// The built-in thigh and the TetGen liver, named, for tests that run on both.
std::vector<std::pair<std::string, Scene>> thigh_and_tetgen_liver() {
  return {{"thigh", make_thigh_scene()}, {"TetGen liver", tetgen_liver()}};
}

// A factorization's history: the interface rows only (a fresh one), optionally where the next
// change is expected.
LinearSolver::History fresh_history(const Framed& f, const std::vector<int>* expected = nullptr) {
  LinearSolver::History h;
  h.interface_rows = f.dense;
  h.expected_rows = expected;
  return h;
}

TEST(FramedCholesky, FrameAroundChangesIsTheChangedRowsAndTheirNeighbours) {
  const Framed f = thigh_matrix();
  const int last = static_cast<int>(f.a.rows()) - 1;
  int neighbours = 0;  // the row itself among them
  for (SparseMatrix::InnerIterator it(f.a, last); it; ++it) ++neighbours;
  EXPECT_EQ(static_cast<int>(f.frame.size()), neighbours);
  EXPECT_TRUE(std::binary_search(f.frame.begin(), f.frame.end(), last));
  ASSERT_GE(f.outside, 0);
  // A changed interface row joins the frame but does not spread it over the dense block.
  ASSERT_GT(f.dense, 0);
  SparseMatrix before = f.a;
  before.coeffRef(0, 0) *= 2;
  EXPECT_EQ(FramedCholesky::frame_around_changes(before, f.a, f.dense, 1), std::vector<int>{0});
  EXPECT_EQ(FramedCholesky::frame_around_changes(before, f.a, 0, 1).size(),
            static_cast<size_t>(f.a.innerVector(0).nonZeros()));
}

// What a refactorization costs (the CPU solver keeps a frame while refactoring it costs less,
// cpu_cg_solver.cpp): CHOLMOD's count, n^3/3 for a dense matrix, O(n) for a tridiagonal one.
TEST(FramedCholesky, CountsTheFlopsOfItsFactorization) {
  constexpr int n = 120;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Constant(n, n, 0.5);
  dense.diagonal().array() += n;
  const SparseMatrix a = dense.sparseView();
  const double cubic = FramedCholesky(a, {}).factor_flops();
  EXPECT_NEAR(cubic / (n * n * n / 3.0), 1.0, 0.1) << cubic;
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) {
    entries.emplace_back(i, i, 4.0);
    if (i > 0) entries.emplace_back(i, i - 1, -1.0), entries.emplace_back(i - 1, i, -1.0);
  }
  SparseMatrix tridiagonal(n, n);
  tridiagonal.setFromTriplets(entries.begin(), entries.end());
  const double linear = FramedCholesky(tridiagonal, {}).factor_flops();
  EXPECT_GT(linear, 0);
  EXPECT_LT(linear, 10.0 * n) << linear;
}

TEST(FramedCholesky, TakesChangesInsideTheFrameAndNewDofsCoupledToIt) {
  const Framed f = thigh_matrix();
  FramedCholesky factor(f.a, f.frame);
  EXPECT_EQ(factor.frame_size(), static_cast<int>(f.frame.size()));
  const Vector b = Vector::LinSpaced(f.a.rows(), 1.0, 2.0);
  EXPECT_LE(relative(factor.solve(b), SparseCholesky(f.a).solve(b)), 1e-12);

  // A stiffer coupling between two frame DOFs and two new DOFs hanging on a third one.
  const int n = static_cast<int>(f.a.rows());
  const int p = f.frame[0], q = f.frame[1], r = f.frame[2];
  std::vector<Eigen::Triplet<double, int>> t;
  for (int i = 0; i < n; ++i)
    for (SparseMatrix::InnerIterator it(f.a, i); it; ++it)
      t.emplace_back(i, static_cast<int>(it.index()), it.value());
  const double d = f.a.coeff(p, p);
  t.emplace_back(p, p, 0.3 * d);
  t.emplace_back(q, q, 0.3 * d);
  t.emplace_back(p, q, -0.3 * d);
  t.emplace_back(q, p, -0.3 * d);
  for (int k : {n, n + 1}) {
    t.emplace_back(k, k, d);
    t.emplace_back(k, r, -0.2 * d);
    t.emplace_back(r, k, -0.2 * d);
    t.emplace_back(r, r, 0.2 * d);
  }
  SparseMatrix grown(n + 2, n + 2);
  grown.setFromTriplets(t.begin(), t.end());
  ASSERT_TRUE(factor.update(grown));
  EXPECT_EQ(factor.rows(), n + 2);
  EXPECT_EQ(factor.frame_size(), static_cast<int>(f.frame.size()) + 2);
  EXPECT_EQ(factor.updates(), 1);
  const Eigen::MatrixXd b2 = two_columns(Vector::LinSpaced(n + 2, -1.0, 3.0));
  EXPECT_LE(relative(factor.solve(b2), SparseCholesky(grown).solve(b2)), 1e-12);
}

// With the changed rows named (what the hybrid model knows after a cut), rows outside the list
// are not compared: a list inside the frame is taken as it is; a row outside it joins the
// frame as an extra row (eq. (28)), and either way the factor solves the new matrix exactly.
TEST(FramedCholesky, TakesTheChangedRowsItIsTold) {
  const Framed f = thigh_matrix();
  SparseMatrix changed = f.a;
  const int p = f.frame[0];
  changed.coeffRef(p, p) *= 1.25;
  const Vector b = Vector::LinSpaced(f.a.rows(), 1.0, 2.0);
  const Vector ref = SparseCholesky(changed).solve(b);
  FramedCholesky inside_only(f.a, f.frame);
  const std::vector<int> inside = {p};
  ASSERT_TRUE(inside_only.update(changed, &inside));
  EXPECT_EQ(inside_only.frame_size(), static_cast<int>(f.frame.size()));
  EXPECT_LE(relative(inside_only.solve(b), ref), 1e-12);
  FramedCholesky with_outside(f.a, f.frame);
  const std::vector<int> outside = {p, f.outside};
  ASSERT_TRUE(with_outside.update(changed, &outside));
  EXPECT_EQ(with_outside.frame_size(), static_cast<int>(f.frame.size()) + 1);
  EXPECT_LE(relative(with_outside.solve(b), ref), 1e-12);
  EXPECT_EQ(FramedCholesky::frame_around(f.a, {static_cast<int>(f.a.rows()) - 1}, f.dense, 1),
            f.frame);
}

// A fresh factorization told where the next change is expected (a moved region's new model,
// LinearSolver::History::expected_rows) frames those rows: a change there then refactors the
// frame alone, exactly; without the hint the same change (more rows than may join a frame)
// refactors the whole matrix.
TEST(FramedCholesky, CpuSolverFramesTheRowsWhereAChangeIsExpected) {
  const Framed f = thigh_matrix();
  const int n = static_cast<int>(f.a.rows());
  const int p = n - 1;  // f.frame is this row and its neighbours; the change reaches two rings
  const std::vector<int> frame = FramedCholesky::frame_around(f.a, {p}, f.dense, 2);
  ASSERT_GT(static_cast<int>(frame.size()), FramedCholesky::kMaxExtraRows);
  SparseMatrix changed = f.a;
  for (int r : frame) changed.coeffRef(r, r) *= 1.25;
  const std::vector<int>& expected = f.frame;  // framed with one ring more: `frame`
  const Vector b = Vector::LinSpaced(n, 1.0, 2.0);
  const Vector ref = SparseCholesky(changed).solve(b);
  for (const bool hint : {true, false}) {
    auto solver = make_cpu_solver();
    solver->set_matrix(f.a, {}, fresh_history(f, hint ? &expected : nullptr));
    LinearSolver::History cut;
    cut.kept_rows = n;
    cut.interface_rows = f.dense;
    cut.changed_rows = &frame;
    solver->set_matrix(changed, {}, cut);
    EXPECT_EQ(solver->frame_updates(), hint ? 1 : 0) << (hint ? "with" : "without") << " the hint";
    Vector x = Vector::Zero(n);
    const CgResult r = solver->solve(b, x, {}, CgSettings{1e-13, 50});
    EXPECT_TRUE(r.converged);
    EXPECT_LE((x - ref).norm() / ref.norm(), 1e-11);
  }
}

// A DOF held (a held free piece) or let go keeps its row in the factored matrix D
// (cpu_cg_solver.cpp): its row and its neighbours' change, which the frame takes like a cut's
// rows. The held DOF keeps its value exactly; the others solve A_ff x_f = b_f - A_fh x_h.
TEST(FramedCholesky, CpuSolverTakesAHeldDofThroughTheFrame) {
  for (const auto& [what, scene] : thigh_and_tetgen_liver()) {
    SCOPED_TRACE(what);
    const Framed f = framed_matrix(scene);
    const int n = static_cast<int>(f.a.rows());
    const int p = n - 1;  // f.frame: p and its neighbours, what holding p changes in D
    const Vector b = Vector::LinSpaced(n, 1.0, 2.0);
    auto solver = make_cpu_solver();
    solver->set_matrix(f.a, {}, fresh_history(f, &f.frame));  // framed with one ring more
    const std::vector<int> none;
    LinearSolver::History same;
    same.kept_rows = n;
    same.interface_rows = f.dense;
    same.changed_rows = &none;  // the matrix is the same; only what is held changes
    std::vector<std::uint8_t> held(static_cast<size_t>(n), 0);
    held[static_cast<size_t>(p)] = 1;
    solver->set_matrix(f.a, held, same);
    EXPECT_EQ(solver->frame_updates(), 1) << "holding a DOF inside the frame refactors it alone";
    Vector x = Vector::Zero(n);
    x[p] = 1e-3;
    std::vector<std::uint8_t> constrained = held;
    const CgResult r = solver->solve(b, x, constrained, CgSettings{1e-12, 50});
    EXPECT_TRUE(r.converged);
    EXPECT_EQ(r.iterations, 1) << "the direct step";
    EXPECT_EQ(x[p], 1e-3);
    Vector residual = b - f.a * x;
    residual[p] = 0;
    EXPECT_LE(residual.norm() / b.norm(), 1e-11);
    // Let go again: the frame takes that too, and the solve is the plain one.
    solver->set_matrix(f.a, {}, same);
    EXPECT_EQ(solver->frame_updates(), 2);
    x.setZero();
    EXPECT_TRUE(solver->solve(b, x, {}, CgSettings{1e-12, 50}).converged);
    const Vector ref = SparseCholesky(f.a).solve(b);
    EXPECT_LE((x - ref).norm() / ref.norm(), 1e-11);
  }
}

// The CPU solver keeps its own copy of A (and of D when DOFs are held) and, told which rows a
// change made (History::changed_rows), copies only the rows from the lowest of them on: after
// changes low and high in the operation rows, a new DOF, a DOF held and a change while it is
// held, each solve equals a fresh direct solve of the true matrix. A stale row in the copy
// would solve another matrix.
TEST(FramedCholesky, CpuSolverCopiesTheRowsAChangeNamesAndKeepsTheRest) {
  for (const auto& [what, scene] : thigh_and_tetgen_liver()) {
    SCOPED_TRACE(what);
    const Framed f = framed_matrix(scene);
    const int n = static_cast<int>(f.a.rows());
    const int p = n - 1, q = f.outside, low = f.dense + 3;
    ASSERT_GT(q, low);
    // A spring between rows i and j (k (e_i - e_j)(e_i - e_j)^T): symmetric, keeps A SPD.
    const auto spring = [](SparseMatrix a, int i, int j, double k) {
      a.coeffRef(i, i) += k;
      a.coeffRef(j, j) += k;
      a.coeffRef(i, j) -= k;
      a.coeffRef(j, i) -= k;
      a.makeCompressed();
      return a;
    };
    const double k = 0.3 * f.a.coeff(p, p);
    auto solver = make_cpu_solver();
    solver->set_matrix(f.a, {}, fresh_history(f));
    const auto expect_solves = [&](const SparseMatrix& a, const std::vector<std::uint8_t>& held,
                                   const std::string& step) {
      const int rows = static_cast<int>(a.rows());
      const Vector b = Vector::LinSpaced(rows, 1.0, 2.0);
      Vector x = Vector::Zero(rows);
      for (int r = 0; r < rows; ++r)
        if (!held.empty() && held[static_cast<size_t>(r)]) x[r] = 1e-3;
      const CgResult res = solver->solve(b, x, held, CgSettings{1e-12, 50});
      EXPECT_TRUE(res.converged) << step;
      // One direct step: exact only with the factor of this matrix (of its D, DOFs held).
      EXPECT_EQ(res.iterations, 1) << step << ": the factor is not of this matrix";
      Vector residual = b - a * x;
      for (int r = 0; r < rows; ++r)
        if (!held.empty() && held[static_cast<size_t>(r)]) {
          EXPECT_EQ(x[r], 1e-3) << step;
          residual[r] = 0;
        }
      EXPECT_LE(residual.norm() / b.norm(), 1e-11) << step << ": the copy is not the matrix";
    };
    LinearSolver::History cut;
    cut.kept_rows = n;
    cut.interface_rows = f.dense;
    // 1. Values alone (the same pattern): a spring between p and a neighbour, and row low's
    // diagonal; then a new coupling between rows far apart.
    const int j = [&] {
      for (SparseMatrix::InnerIterator it(f.a, p); it; ++it)
        if (it.index() != p && it.index() >= f.dense) return static_cast<int>(it.index());
      return -1;
    }();
    ASSERT_GE(j, 0);
    SparseMatrix a0 = spring(f.a, p, j, k);
    a0.coeffRef(low, low) *= 1.25;
    ASSERT_EQ(a0.nonZeros(), f.a.nonZeros());
    const std::vector<int> rows0 = {p, j, low};
    cut.changed_rows = &rows0;
    solver->set_matrix(a0, {}, cut);
    expect_solves(a0, {}, "values of rows p, j and low");
    const SparseMatrix a1 = spring(a0, p, q, k);
    const std::vector<int> rows1 = {q, p};
    cut.changed_rows = &rows1;
    solver->set_matrix(a1, {}, cut);
    expect_solves(a1, {}, "a change of rows q and p");
    // 2. A new DOF coupled to p (a cut appends its new nodes' DOFs).
    SparseMatrix a2 = a1;
    a2.conservativeResize(n + 1, n + 1);
    a2 = spring(a2, p, n, k);
    const std::vector<int> rows2 = {p, n};
    cut.changed_rows = &rows2;
    solver->set_matrix(a2, {}, cut);
    expect_solves(a2, {}, "a new DOF");
    // 3. The same matrix, q held: D's rows change from q's lowest neighbour on.
    std::vector<std::uint8_t> held(static_cast<size_t>(n + 1), 0);
    held[static_cast<size_t>(q)] = 1;
    const std::vector<int> none;
    cut.kept_rows = n + 1;
    cut.changed_rows = &none;
    solver->set_matrix(a2, held, cut);
    expect_solves(a2, held, "q held");
    // 4. While q is held, a change low in the operation rows (D rewritten from there on).
    const SparseMatrix a3 = spring(a2, low, p, k);
    const std::vector<int> rows3 = {p, low};
    cut.changed_rows = &rows3;
    solver->set_matrix(a3, held, cut);
    expect_solves(a3, held, "a low row while q is held");
    // 5. j held as well (the held set changes while D exists; the matrix does not).
    held[static_cast<size_t>(j)] = 1;
    cut.changed_rows = &none;
    solver->set_matrix(a3, held, cut);
    expect_solves(a3, held, "j held too");
    // 6. Let go of both, no other change.
    solver->set_matrix(a3, {}, cut);
    expect_solves(a3, {}, "q let go");
  }
}

// Rows outside the frame join it as extra rows, one change after another, and new DOFs may
// couple to them; each time the factor solves the new matrix as exactly as a fresh one.
TEST(FramedCholesky, TakesAFewRowsOutsideTheFrameOneChangeAfterAnother) {
  const Framed f = thigh_matrix();
  FramedCholesky factor(f.a, f.frame);
  const int n = static_cast<int>(f.a.rows());
  SparseMatrix changed = f.a;  // a stiffer DOF outside the frame
  changed.coeffRef(f.outside, f.outside) *= 1.5;
  ASSERT_TRUE(factor.update(changed));
  EXPECT_EQ(factor.frame_size(), static_cast<int>(f.frame.size()) + 1);
  const Vector b = Vector::LinSpaced(n, 1.0, 2.0);
  EXPECT_LE(relative(factor.solve(b), SparseCholesky(changed).solve(b)), 1e-12);

  // A new DOF coupled to that row and to another row outside the frame, with a stiffer
  // coupling between the two.
  int other = -1;
  std::vector<char> in(static_cast<size_t>(n), 0);
  for (int r : f.frame) in[static_cast<size_t>(r)] = 1;
  for (int r = f.outside - 1; r >= f.dense && other < 0; --r)
    if (!in[static_cast<size_t>(r)] && changed.coeff(r, f.outside) != 0) other = r;
  ASSERT_GE(other, 0);
  std::vector<Eigen::Triplet<double, int>> t;
  for (int i = 0; i < n; ++i)
    for (SparseMatrix::InnerIterator it(changed, i); it; ++it)
      t.emplace_back(i, static_cast<int>(it.index()), it.value());
  const double d = f.a.coeff(f.outside, f.outside);
  t.emplace_back(n, n, d);
  t.emplace_back(n, f.outside, -0.1 * d);
  t.emplace_back(f.outside, n, -0.1 * d);
  t.emplace_back(f.outside, f.outside, 0.1 * d);
  t.emplace_back(other, other, 0.2 * d);
  t.emplace_back(other, f.outside, -0.1 * d);
  t.emplace_back(f.outside, other, -0.1 * d);
  SparseMatrix grown(n + 1, n + 1);
  grown.setFromTriplets(t.begin(), t.end());
  ASSERT_TRUE(factor.update(grown));
  EXPECT_EQ(factor.frame_size(), static_cast<int>(f.frame.size()) + 3);
  EXPECT_EQ(factor.updates(), 2);
  const Eigen::MatrixXd b2 = two_columns(Vector::LinSpaced(n + 1, -1.0, 3.0));
  EXPECT_LE(relative(factor.solve(b2), SparseCholesky(grown).solve(b2)), 1e-12);
  EXPECT_LE(
      relative(factor.solve(Vector(b2.col(0))), SparseCholesky(grown).solve(Vector(b2.col(0)))),
      1e-12);
}

TEST(FramedCholesky, RefusesMoreRowsOutsideTheFrameAndKeepsItsFactor) {
  const Framed f = thigh_matrix();
  FramedCholesky factor(f.a, f.frame);
  const int n = static_cast<int>(f.a.rows());
  const Vector b = Vector::LinSpaced(n, 1.0, 2.0);
  const Vector ref = SparseCholesky(f.a).solve(b);

  // More stiffer DOFs outside the frame than may join it.
  SparseMatrix changed = f.a;
  std::vector<char> in(static_cast<size_t>(n), 0);
  for (int r : f.frame) in[static_cast<size_t>(r)] = 1;
  int outside = 0;
  for (int r = n - 1; r >= f.dense && outside <= FramedCholesky::kMaxExtraRows; --r)
    if (!in[static_cast<size_t>(r)]) changed.coeffRef(r, r) *= 1.5, ++outside;
  EXPECT_FALSE(factor.update(changed));

  // A frame that is no longer positive definite.
  SparseMatrix indefinite = f.a;
  indefinite.coeffRef(f.frame[0], f.frame[0]) = -1.0;
  EXPECT_FALSE(factor.update(indefinite));
  // Nor with an extra row (the Schur complement is refused, the extra row not kept).
  indefinite.coeffRef(f.outside, f.outside) *= 1.5;
  EXPECT_FALSE(factor.update(indefinite));
  EXPECT_EQ(factor.frame_size(), static_cast<int>(f.frame.size()));

  // Fewer rows than factored.
  EXPECT_FALSE(factor.update(SparseMatrix(f.a.topLeftCorner(n - 1, n - 1))));

  EXPECT_EQ(factor.updates(), 0);
  EXPECT_EQ(factor.rows(), n);
  EXPECT_LE(relative(factor.solve(b), ref), 1e-12);  // still the factor of f.a
}

// The solver after each cut of a stroke: most cuts refactor the frame only
// (LinearSolver::frame_updates), and the hybrid solution equals a direct solve of the hybrid
// system the model holds after the stroke (the tests of hybrid_model.hpp compare that system
// with the full model).
TEST(FramedCholesky, CpuSolverTakesMostCutsThroughTheFrame) {
  const Scene scene = thigh_stroke();
  Simulation sim(scene);
  int cuts = 0;
  for (const BladePose& pose : scene.trajectory) {
    const StepStats s = sim.step(pose);
    cuts += s.cutting;
    ASSERT_TRUE(s.converged) << s.solver_message;
    EXPECT_LE(s.residual, 1e-10);
  }
  const int updates = sim.model().solver().frame_updates();
  EXPECT_GE(cuts, 10);
  EXPECT_GE(2 * updates, cuts) << updates << " of " << cuts << " cuts updated the frame";
  // The last solve is exact: the solution solves the hybrid system with the blade's imposed
  // displacements to the tolerance (residual above), and with none after it leaves.
  const StepStats idle = sim.step(std::nullopt);
  EXPECT_TRUE(idle.converged);
  const HybridModel& h = sim.model();
  const DofMap& dofs = h.hybrid_dofs();
  Vector u(dofs.rows());
  std::vector<std::uint8_t> held(static_cast<size_t>(dofs.rows()), 0);
  for (int r = 0; r < dofs.rows(); ++r) {
    const int g = dofs.global_of[static_cast<size_t>(r)];
    u[r] = h.operation_displacement()[g];
    held[static_cast<size_t>(r)] = h.held_nodes()[static_cast<size_t>(g / 3)];
  }
  Vector x = u;  // held pieces' DOFs keep their values
  solve_direct(h.hybrid_matrix(), h.hybrid_rhs(), x, held);
  EXPECT_LE((u - x).norm() / x.norm(), 1e-9);
}

}  // namespace
}  // namespace stc
