// The "gl" LinearSolver's promise (gl_solver.hpp): float32 CG on the GPU plus double iterative
// refinement reaches the requested tolerance on SPD systems with condition numbers up to 1e8
// and right-hand sides from 1e-9 to 1e3 in norm, or hands that solve to the CPU with a
// one-line reason; and a solve that stopped short is never reported converged.
// Systems come from Eigen: A = Q diag(lambda) Q^T with a random orthogonal Q (dense, n = 48,
// eigenvalues log-spaced over the condition number), and badly scaled sparse elasticity-like
// matrices D S D (D spans 1e-3..1e3, so cond(A) ~ 1e12 cond(S) while the Jacobi-scaled system
// is S itself). Each result is checked against a residual recomputed here in double.
#include "soft_tissue_cutting/gpu/gl_solver.hpp"
#include "soft_tissue_cutting/gpu/test_matrices.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include <cmath>
#include <cstdio>
#include <random>

namespace stc {
namespace {

// Q diag(lambda) Q^T, lambda_k = kappa^(-k/(n-1)): eigenvalues 1 .. 1/kappa.
SparseMatrix spectral_spd(int n, double kappa, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  Eigen::MatrixXd m(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) m(i, j) = g(rng);
  const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(m).householderQ();
  Eigen::VectorXd lambda(n);
  for (int k = 0; k < n; ++k) lambda[k] = std::pow(kappa, -double(k) / (n - 1));
  Eigen::MatrixXd a = q * lambda.asDiagonal() * q.transpose();
  a = 0.5 * (a + a.transpose());  // exactly symmetric
  return a.sparseView();
}

// D S D with log-uniform D in [1e-3, 1e3]: units as different as Pa and mN make.
SparseMatrix badly_scaled(const SparseMatrix& s, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-3, 3);
  Vector d(s.rows());
  for (Eigen::Index i = 0; i < d.size(); ++i) d[i] = std::pow(10.0, u(rng));
  SparseMatrix a = d.asDiagonal() * s * d.asDiagonal();
  a.makeCompressed();
  return a;
}

double condition_number(const SparseMatrix& a) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es{Eigen::MatrixXd(a), Eigen::EigenvaluesOnly};
  return es.eigenvalues().maxCoeff() / es.eigenvalues().minCoeff();
}

std::unique_ptr<LinearSolver> gl_solver(const GlSolverOptions& options = {}) {
  std::string why;
  auto s = make_gl_solver(options, &why);
  EXPECT_TRUE(s) << "EGL/GL must work on llvmpipe here: " << why;
  return s;
}

// The invariants every result must keep, whatever solved it.
void expect_honest(const CgResult& r, const SparseMatrix& a, const Vector& b, const Vector& x,
                   const CgSettings& settings) {
  const double true_res = (b - a * x).norm() / b.norm();
  EXPECT_TRUE(x.allFinite());
  EXPECT_NEAR(r.residual, true_res, 1e-3 * true_res + 1e-300)
      << "reported residual is not the true one";
  EXPECT_EQ(r.converged, true_res <= settings.tolerance)
      << "converged=" << r.converged << " with true residual " << true_res;
  EXPECT_LE(r.iterations, settings.max_iterations);
  EXPECT_TRUE(r.solved_by == "gl" || r.solved_by == "cpu") << r.solved_by;
  EXPECT_EQ(r.solved_by == "cpu", !r.fallback_reason.empty()) << r.fallback_reason;
  EXPECT_EQ(r.fallback_reason.find('\n'), std::string::npos);
  EXPECT_EQ(r.converged, r.message.empty()) << r.message;
  EXPECT_EQ(r.message.find('\n'), std::string::npos);
}

struct SweepCase {
  double kappa;
  double rhs_norm;
};

class GlRefinementSweep : public ::testing::TestWithParam<SweepCase> {};

TEST_P(GlRefinementSweep, SpectralSpdReachesTheToleranceOrFallsBackWithAReason) {
  const SweepCase c = GetParam();
  const SparseMatrix a = spectral_spd(48, c.kappa, 7);
  const double kappa = condition_number(a);
  ASSERT_NEAR(std::log10(kappa), std::log10(c.kappa), 0.05);
  const Vector b = c.rhs_norm * gpu::random_vector(a.rows(), 11).normalized();
  auto s = gl_solver();
  ASSERT_TRUE(s);
  s->set_matrix(a);
  Vector x = Vector::Zero(a.rows());
  // Even double cannot push ||b - A x|| / ||b|| much below eps_double * cond (a random b
  // excites the smallest eigenvalues): ask for 1e-10 or what double can reach, if more.
  const CgSettings settings{std::max(1e-10, 1e-15 * kappa), 20000};
  const CgResult r = s->solve(b, x, {}, settings);
  std::printf("kappa %.1e |b| %.0e: %s, %d iterations, residual %.2e%s%s\n", kappa, c.rhs_norm,
              r.solved_by.c_str(), r.iterations, r.residual, r.fallback_reason.empty() ? "" : "; ",
              r.fallback_reason.c_str());
  expect_honest(r, a, b, x, settings);
  EXPECT_TRUE(r.converged);
  // Error vs a double LDL^T solve: at most what the condition number allows.
  const Vector ref = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(a).solve(b);
  EXPECT_LE((x - ref).norm() / ref.norm(), 10 * kappa * settings.tolerance);
  // float32 is enough for the GPU to finish by itself up to cond ~1e4 (eps_float * cond << 1).
  if (kappa <= 1.01e4) {
    EXPECT_EQ(r.solved_by, "gl") << r.fallback_reason;
  }
}

INSTANTIATE_TEST_SUITE_P(KappaAndRhs, GlRefinementSweep,
                         ::testing::Values(SweepCase{1e2, 1e-9}, SweepCase{1e2, 1e3},
                                           SweepCase{1e4, 1e-9}, SweepCase{1e4, 1.0},
                                           SweepCase{1e4, 1e3}, SweepCase{1e6, 1e-9},
                                           SweepCase{1e6, 1e3}, SweepCase{1e8, 1e-9},
                                           SweepCase{1e8, 1.0}, SweepCase{1e8, 1e3}),
                         [](const ::testing::TestParamInfo<SweepCase>& i) {
                           char buf[64];
                           std::snprintf(buf, sizeof buf, "kappa1e%d_rhs1e%d",
                                         int(std::lround(std::log10(i.param.kappa))),
                                         int(std::lround(std::log10(i.param.rhs_norm))));
                           std::string name = buf;
                           for (char& ch : name)
                             if (ch == '-') ch = 'm';
                           return name;
                         });

TEST(GlRefinement, BadlyScaledSparseSystemsSolveOnTheGpu) {
  // Jacobi scaling on the GPU side undoes D: float sees S, cond ~1e2, whatever |b|.
  const SparseMatrix a = badly_scaled(gpu::elasticity_like(6 * 6 * 6, 6, 6), 5);  // 648 DOF
  const double kappa = condition_number(a);
  EXPECT_GT(kappa, 1e8);
  auto s = gl_solver();
  ASSERT_TRUE(s);
  s->set_matrix(a);
  for (double rhs_norm : {1e-9, 1e-3, 1e3}) {
    const Vector b = rhs_norm * gpu::random_vector(a.rows(), 3).normalized();
    Vector x = Vector::Zero(a.rows());
    const CgSettings settings{1e-10, 5000};
    const CgResult r = s->solve(b, x, {}, settings);
    std::printf("D S D, kappa %.1e, |b| %.0e: %s, %d iterations, residual %.2e\n", kappa, rhs_norm,
                r.solved_by.c_str(), r.iterations, r.residual);
    expect_honest(r, a, b, x, settings);
    EXPECT_TRUE(r.converged);
    EXPECT_EQ(r.solved_by, "gl") << r.fallback_reason;
  }
}

TEST(GlRefinement, IterationCapIsReportedNotConvergedWithoutFallback) {
  const SparseMatrix a = gpu::elasticity_like(8 * 8 * 8, 8, 8);
  auto s = gl_solver();
  ASSERT_TRUE(s);
  s->set_matrix(a);
  const Vector b = gpu::random_vector(a.rows(), 1);
  for (int cap : {1, 5, 20}) {
    Vector x = Vector::Zero(a.rows());
    const CgSettings settings{1e-10, cap};
    const CgResult r = s->solve(b, x, {}, settings);
    expect_honest(r, a, b, x, settings);
    EXPECT_FALSE(r.converged) << "cap " << cap;
    EXPECT_EQ(r.solved_by, "gl");  // running out of iterations is not float's fault
    EXPECT_NE(r.message.find("max_iterations"), std::string::npos) << r.message;
    EXPECT_GT(r.residual, 1e-10);
  }
}

TEST(GlRefinement, FloatLimitWithoutFallbackIsNotConverged) {
  // cond 1e10: far beyond float32 (eps_float * cond ~ 600). With the fallback off the solver must
  // say so rather than claim convergence; with it on, the CPU finishes the solve.
  const SparseMatrix a = spectral_spd(48, 1e10, 9);
  const Vector b = gpu::random_vector(a.rows(), 5);
  const CgSettings settings{1e-5, 20000};  // what double reaches at cond 1e10 (see above)
  GlSolverOptions no_fallback;
  no_fallback.cpu_fallback = false;
  auto s = gl_solver(no_fallback);
  ASSERT_TRUE(s);
  s->set_matrix(a);
  Vector x = Vector::Zero(a.rows());
  CgResult r = s->solve(b, x, {}, settings);
  expect_honest(r, a, b, x, settings);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.solved_by, "gl");
  EXPECT_NE(r.message.find("float32"), std::string::npos) << r.message;

  auto f = gl_solver();
  ASSERT_TRUE(f);
  f->set_matrix(a);
  x.setZero();
  r = f->solve(b, x, {}, settings);
  std::printf("kappa 1e10: %s after %d iterations, residual %.2e; %s\n", r.solved_by.c_str(),
              r.iterations, r.residual, r.fallback_reason.c_str());
  expect_honest(r, a, b, x, settings);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.solved_by, "cpu");
  EXPECT_NE(r.fallback_reason.find("float32"), std::string::npos) << r.fallback_reason;
}

TEST(GlRefinement, MatrixBeyondTheTextureLimitIsSolvedOnTheCpuWithAReason) {
  const SparseMatrix a = gpu::elasticity_like(8 * 8 * 8, 8, 8);  // 1536 DOF: 64 x 24 texels
  GlSolverOptions small;
  small.max_texture_size = 16;
  auto s = gl_solver(small);
  ASSERT_TRUE(s);
  s->set_matrix(a);  // does not throw: the solves go to the CPU
  const Vector b = gpu::random_vector(a.rows(), 2);
  Vector x = Vector::Zero(a.rows());
  const CgSettings settings{1e-10, 2000};
  const CgResult r = s->solve(b, x, {}, settings);
  expect_honest(r, a, b, x, settings);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.solved_by, "cpu");
  EXPECT_NE(r.fallback_reason.find("texture size limit"), std::string::npos) << r.fallback_reason;
}

}  // namespace
}  // namespace stc
