// The direct solve with held DOFs through the factor of the whole hybrid matrix and a
// capacitance system on the held DOFs (docs/DESIGN.md eqs. (24)-(25), solve/held_dof_solve.hpp)
// against the reference direct solve of the reduced system (14), on the thigh and on a TetGen
// liver; the Cholesky-preconditioned CPU solver takes it as its one exact step; the kept
// columns of A^-1 E_c are reused while the same DOFs stay held and dropped with the matrix.
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/solve/held_dof_solve.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace stc {
namespace {

// sofa_liver2.obj through TetGen (coarse, for test speed), 15 cm, lowest 10 % in x fixed,
// gravity, an operation sphere of 2.5 cm around its middle.
Scene tetgen_liver() {
  Scene s;
  s.source = "sofa_liver2.obj";
  MeshReadOptions options;
  options.tetgen_switches = "pq1.4/10Q";
  s.mesh = read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/sofa_liver2.obj", options);
  Vec3 lo = s.mesh.nodes[0], hi = lo;
  for (const Vec3& x : s.mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const double scale = 0.15 / (hi - lo).maxCoeff();
  for (Vec3& x : s.mesh.nodes) x = (x - lo) * scale;
  hi = (hi - lo) * scale;
  s.material = Material{3000.0, 0.45, 1000.0};
  NodeSelector fixed;
  fixed.kind = NodeSelector::Kind::kBox;
  fixed.box = Box{Vec3::Constant(-1), Vec3(0.1 * hi.x(), 1, 1)};
  s.fixed.push_back(fixed);
  s.gravity = Vec3(0, -9.81, 0);
  s.operation_region.kind = OperationRegion::Kind::kSphere;
  s.operation_region.sphere = Sphere{0.5 * hi, 0.025};
  return s;
}

// Rows of a contact patch: the first `count` operation nodes plus one interface node.
std::vector<int> held_rows(const HybridModel& h, size_t count, size_t skip = 0) {
  std::vector<int> nodes;
  for (size_t k = skip; k < h.partition().operation.size() && nodes.size() < count; ++k)
    nodes.push_back(h.partition().operation[k]);
  nodes.push_back(h.partition().interface.at(skip));
  std::vector<int> rows;
  for (int node : nodes)
    for (int c = 0; c < 3; ++c) {
      const int r = h.hybrid_dofs().row_of[static_cast<size_t>(3 * node + c)];
      if (r >= 0) rows.push_back(r);
    }
  return rows;
}

double relative(const Vector& x, const Vector& ref) { return (x - ref).norm() / ref.norm(); }

void check_model(const HybridModel& h) {
  const SparseMatrix& a = h.hybrid_matrix();
  const Vector& b = h.hybrid_rhs();
  const int n = static_cast<int>(a.rows());
  ASSERT_GT(n, 0);
  const SparseCholesky factor(a);
  HeldDofSolve held;
  auto cg = make_cpu_solver();
  cg->set_matrix(a);
  int kept = 0;
  for (int press = 0; press < 3; ++press) {
    SCOPED_TRACE("press " + std::to_string(press));
    // Presses 0 and 1 hold the same DOFs (deeper), press 2 slides one node further.
    const std::vector<int> rows = held_rows(h, 3, press == 2 ? 1 : 0);
    std::vector<std::uint8_t> constrained(static_cast<size_t>(n), 0);
    Vector x0 = Vector::Zero(n);
    for (int r : rows) {
      constrained[static_cast<size_t>(r)] = 1;
      x0[r] = -1e-3 * (1 + press) * (1 + 0.3 * std::sin(r));
    }
    Vector ref = x0;
    solve_direct(a, b, ref, constrained);

    Vector x = x0;
    held.solve(factor, b, rows, x);
    EXPECT_LE(relative(x, ref), 1e-10);
    for (int r : rows) EXPECT_EQ(x[r], x0[r]);  // held values kept exactly
    if (press == 1) {
      EXPECT_EQ(held.kept_columns(), kept);  // same DOFs: no new column
    }
    if (press == 2) {
      EXPECT_GT(held.kept_columns(), kept);
    }
    kept = held.kept_columns();

    Vector y = x0;
    const CgResult r = cg->solve(b, y, constrained, CgSettings{1e-10, 2000});
    EXPECT_TRUE(r.converged) << r.message;
    EXPECT_EQ(r.iterations, 1);  // the direct step met the tolerance
    EXPECT_LE(r.residual, 1e-10);
    EXPECT_LE(relative(y, ref), 1e-10);
  }
  held.reset();
  EXPECT_EQ(held.kept_columns(), 0);
}

TEST(HeldDofSolve, EqualsDirectSolveOnThigh) {
  const HybridModel h(make_thigh_scene());
  check_model(h);
}

TEST(HeldDofSolve, EqualsDirectSolveOnTetgenLiver) {
  const HybridModel h(tetgen_liver());
  EXPECT_GT(h.partition().interface.size(), 10u);
  check_model(h);
}

// No held DOF: x = A^-1 b, the cached y, still exact after the matrix changed (reset()).
TEST(HeldDofSolve, UnconstrainedAndAfterNewMatrix) {
  const HybridModel h(make_thigh_scene());
  const SparseMatrix& a = h.hybrid_matrix();
  Vector ref;
  solve_direct(a, h.hybrid_rhs(), ref);
  HeldDofSolve held;
  Vector x = Vector::Zero(a.rows());
  held.solve(SparseCholesky(a), h.hybrid_rhs(), {}, x);
  EXPECT_LE(relative(x, ref), 1e-10);
  const SparseMatrix a2 = 2.0 * a;  // a stiffer material: half the displacement
  held.reset();
  held.solve(SparseCholesky(a2), h.hybrid_rhs(), {}, x);
  EXPECT_LE(relative(x, 0.5 * ref), 1e-10);
}

}  // namespace
}  // namespace stc
