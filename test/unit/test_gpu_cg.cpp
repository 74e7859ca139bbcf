// The "gl" LinearSolver (whole CG on the GPU + double refinement, docs/DESIGN.md section 9) on
// Mesa llvmpipe, against a direct double solve (Eigen SimplicialLDLT of the reduced system).
#include "soft_tissue_cutting/gpu/gl_solver.hpp"
#include "soft_tissue_cutting/gpu/test_matrices.hpp"

#include <gtest/gtest.h>
#include <Eigen/SparseCholesky>

#include <cstdlib>
#include <random>

namespace stc {
namespace {

using gpu::random_vector;

// Reference: A_ff x_f = b_f - A_fc x_c by sparse LDL^T in double.
Vector reference_solve(const SparseMatrix& a, const Vector& b, const Vector& x0,
                       const std::vector<std::uint8_t>& constrained) {
  const int n = int(a.rows());
  std::vector<int> free_ids, index(n, -1);
  for (int i = 0; i < n; ++i)
    if (constrained.empty() || !constrained[i]) {
      index[i] = int(free_ids.size());
      free_ids.push_back(i);
    }
  Vector xc = x0;
  for (int i : free_ids) xc[i] = 0;
  const Vector rhs_full = b - a * xc;
  std::vector<Eigen::Triplet<double>> t;
  for (int i : free_ids)
    for (SparseMatrix::InnerIterator it(a, i); it; ++it)
      if (index[it.col()] >= 0) t.emplace_back(index[i], index[it.col()], it.value());
  Eigen::SparseMatrix<double> aff(int(free_ids.size()), int(free_ids.size()));
  aff.setFromTriplets(t.begin(), t.end());
  Vector rhs(free_ids.size());
  for (std::size_t k = 0; k < free_ids.size(); ++k) rhs[k] = rhs_full[free_ids[k]];
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(aff);
  const Vector xf = ldlt.solve(rhs);
  Vector x = x0;
  for (std::size_t k = 0; k < free_ids.size(); ++k) x[free_ids[k]] = xf[k];
  return x;
}

struct Case {
  gpu::SpmvLayout layout;
  bool dense_block;
};

class GpuCg : public ::testing::TestWithParam<Case> {
 protected:
  SparseMatrix matrix() const {
    const SparseMatrix s = gpu::elasticity_like(8 * 8 * 8, 8, 8);  // 1536 DOF
    return GetParam().dense_block ? gpu::with_dense_block(s, 200, 5) : s;
  }
  std::unique_ptr<LinearSolver> solver() const {
    GlSolverOptions o;
    o.layout = GetParam().layout;
    std::string why;
    auto s = make_gl_solver(o, &why);
    EXPECT_TRUE(s) << "EGL/GL must work on llvmpipe here: " << why;
    return s;
  }
};

TEST_P(GpuCg, MatchesDirectSolve) {
  auto s = solver();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->backend(), "gl");
  EXPECT_FALSE(s->renderer().empty());
  const SparseMatrix a = matrix();
  s->set_matrix(a);
  const Vector b = random_vector(int(a.rows()), 1);
  Vector x = Vector::Zero(a.rows());
  const CgResult r = s->solve(b, x, {}, CgSettings{});
  const Vector ref = reference_solve(a, b, Vector::Zero(a.rows()), {});
  const double err = (x - ref).norm() / ref.norm();
  std::printf("[%s%s] N=%d: %d GPU iterations, true residual %.3g, |x-ref|/|ref| %.3g (%s)\n",
              gpu::layout_name(GetParam().layout).c_str(), GetParam().dense_block ? ", dense" : "",
              int(a.rows()), r.iterations, r.residual, err, s->renderer().c_str());
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.residual, 1e-10);
  EXPECT_LE(err, 1e-5);
}

TEST_P(GpuCg, ConstrainedDofsKeepTheirValues) {
  auto s = solver();
  ASSERT_TRUE(s);
  const SparseMatrix a = matrix();
  s->set_matrix(a);
  const int n = int(a.rows());
  const Vector b = random_vector(n, 2);
  std::vector<std::uint8_t> constrained(n, 0);
  Vector x = Vector::Zero(n);
  // Fix the first node layer (like the bone) and a few scattered DOFs at imposed values.
  for (int i = 0; i < n; ++i)
    if (i < 3 * 64 || i % 37 == 0) {
      constrained[i] = 1;
      x[i] = 0.01 * (i % 5);
    }
  const Vector x0 = x;
  const CgResult r = s->solve(b, x, constrained, CgSettings{});
  const Vector ref = reference_solve(a, b, x0, constrained);
  const double err = (x - ref).norm() / ref.norm();
  std::printf("[%s%s] constrained: %d iterations, residual %.3g, |x-ref|/|ref| %.3g\n",
              gpu::layout_name(GetParam().layout).c_str(), GetParam().dense_block ? ", dense" : "",
              r.iterations, r.residual, err);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(err, 1e-5);
  for (int i = 0; i < n; ++i)
    if (constrained[i]) {
      ASSERT_EQ(x[i], x0[i]) << "constrained DOF " << i << " moved";
    }
}

TEST_P(GpuCg, SetMatrixAfterChangeGivesNewSolution) {
  auto s = solver();
  ASSERT_TRUE(s);
  const SparseMatrix a = matrix();
  const Vector b = random_vector(int(a.rows()), 3);
  s->set_matrix(a);
  Vector x = Vector::Zero(a.rows());
  ASSERT_TRUE(s->solve(b, x, {}, CgSettings{}).converged);
  // Same pattern, new values (stiffness rescaled, textures patched), then a new pattern.
  SparseMatrix a2 = a;
  for (int i = 0; i < 30; ++i) a2.coeffRef(i, i) *= 3.0;
  s->set_matrix(a2);
  ASSERT_TRUE(s->solve(b, x, {}, CgSettings{}).converged);  // warm start from the old x
  EXPECT_LE((x - reference_solve(a2, b, Vector::Zero(a.rows()), {})).norm() /
                reference_solve(a2, b, Vector::Zero(a.rows()), {}).norm(),
            1e-5);
  const SparseMatrix a3 = gpu::elasticity_like(7 * 7 * 7, 7, 7);
  s->set_matrix(a3);
  const Vector b3 = random_vector(int(a3.rows()), 4);
  Vector x3;
  ASSERT_TRUE(s->solve(b3, x3, {}, CgSettings{}).converged);
  const Vector ref3 = reference_solve(a3, b3, Vector::Zero(a3.rows()), {});
  EXPECT_LE((x3 - ref3).norm() / ref3.norm(), 1e-5);
}

INSTANTIATE_TEST_SUITE_P(
    Layouts, GpuCg,
    ::testing::Values(Case{gpu::SpmvLayout::MethodA, false}, Case{gpu::SpmvLayout::MethodB, true},
                      Case{gpu::SpmvLayout::RowLoop, false}, Case{gpu::SpmvLayout::RowLoop, true}),
    [](const ::testing::TestParamInfo<Case>& i) {
      return gpu::layout_name(i.param.layout) + (i.param.dense_block ? "_dense" : "");
    });

TEST(GpuFallback, ForcedNoEglGivesNullAndOneLineReason) {
  setenv("TISSUE_FORCE_NO_EGL", "1", 1);
  std::string why;
  auto s = make_gl_solver(&why);
  unsetenv("TISSUE_FORCE_NO_EGL");
  EXPECT_FALSE(s);
  EXPECT_FALSE(why.empty());
  EXPECT_EQ(why.find('\n'), std::string::npos);
  EXPECT_NE(why.find("TISSUE_FORCE_NO_EGL"), std::string::npos);
}

TEST(GpuFallback, BadShaderDirEnvFallsBackToBuildTree) {
  // $TISSUE_SHADER_DIR comes first; the build-tree folder still serves as fallback.
  setenv("TISSUE_SHADER_DIR", "/nonexistent/shaders", 1);
  std::string why;
  auto s = make_gl_solver(&why);
  unsetenv("TISSUE_SHADER_DIR");
  EXPECT_TRUE(s) << why;
}

}  // namespace
}  // namespace stc
