// Linear tet element stiffness (docs/DESIGN.md section 2): symmetry, rigid-body null space, patch
// test.
#include "soft_tissue_cutting/assembly/element_cache.hpp"
#include "soft_tissue_cutting/assembly/global_assembly.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <numeric>

namespace stc {
namespace {

const Vec3 kX0(0.01, -0.02, 0.03), kX1(0.9, 0.1, -0.05), kX2(0.2, 1.1, 0.15), kX3(0.05, 0.3, 0.8);

TEST(FemElement, SymmetricPositiveSemidefinite) {
  const Mat12 k = element_stiffness(kX0, kX1, kX2, kX3, 3000.0, 0.45);
  EXPECT_LE((k - k.transpose()).norm(), 1e-14 * k.norm());
  Eigen::SelfAdjointEigenSolver<Mat12> eig(k);
  const auto& ev = eig.eigenvalues();  // ascending
  // Exactly six zero eigenvalues (rigid-body modes), six positive deformation modes.
  for (int i = 0; i < 6; ++i) EXPECT_LE(std::abs(ev[i]), 1e-12 * ev[11]) << i;
  for (int i = 6; i < 12; ++i) EXPECT_GT(ev[i], 1e-6 * ev[11]) << i;
}

TEST(FemElement, RigidBodyModesInNullSpace) {
  const Mat12 k = element_stiffness(kX0, kX1, kX2, kX3, 1e4, 0.3);
  const Vec3 x[4] = {kX0, kX1, kX2, kX3};
  for (int mode = 0; mode < 6; ++mode) {
    Eigen::Matrix<double, 12, 1> u;
    for (int a = 0; a < 4; ++a) {
      Vec3 d = Vec3::Zero();
      if (mode < 3)
        d[mode] = 1.0;  // translations
      else
        d = Vec3::Unit(mode - 3).cross(x[a]);  // infinitesimal rotations
      u.segment<3>(3 * a) = d;
    }
    EXPECT_LE((k * u).norm(), 1e-12 * k.norm() * u.norm()) << "mode " << mode;
  }
}

TEST(FemElement, MatchesLameFormula) {
  // K_ab = V (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I): an independent form of
  // V B^T D B with engineering shear.
  const double e = 2500.0, nu = 0.35;
  const Mat12 k = element_stiffness(kX0, kX1, kX2, kX3, e, nu);
  const StrainDisplacement b = strain_displacement(kX0, kX1, kX2, kX3);
  const LameParameters l = lame_parameters(e, nu);
  const double v = signed_volume(kX0, kX1, kX2, kX3);
  for (int a = 0; a < 4; ++a)
    for (int c = 0; c < 4; ++c) {
      const Vec3 ga(b(0, 3 * a), b(1, 3 * a + 1), b(2, 3 * a + 2));
      const Vec3 gc(b(0, 3 * c), b(1, 3 * c + 1), b(2, 3 * c + 2));
      const Eigen::Matrix3d ref = v * (l.lambda * ga * gc.transpose() + l.mu * gc * ga.transpose() +
                                       l.mu * ga.dot(gc) * Eigen::Matrix3d::Identity());
      EXPECT_LE((k.block<3, 3>(3 * a, 3 * c) - ref).norm(), 1e-12 * k.norm());
    }
  EXPECT_NEAR(l.lambda, e * nu / ((1 + nu) * (1 - 2 * nu)), 1e-12 * e);
  EXPECT_NEAR(l.mu, e / (2 * (1 + nu)), 1e-12 * e);
}

TEST(FemElement, PatchTestOnBoxMesh) {
  GeneratorParams g;
  g.size = Vec3(0.3, 0.2, 0.25);
  g.cells = {4, 3, 3};
  const TetMesh mesh = make_box_mesh(g);
  // Perturb interior nodes so the patch is irregular.
  TetMesh m = mesh;
  for (int n = 0; n < m.num_nodes(); ++n) {
    const Vec3& x = mesh.nodes[n];
    const bool interior = (x.array() > 1e-12).all() && (x.array() < g.size.array() - 1e-12).all();
    if (interior)
      m.nodes[n] += 0.01 * Vec3(std::sin(7.0 * n), std::cos(3.0 * n), std::sin(5.0 * n + 1));
  }
  for (int t = 0; t < m.num_tets(); ++t) ASSERT_GT(tet_volume(m, t), 0);
  const Material mat{1e4, 0.3, 1000};
  const ElementStiffnessCache cache(m, mat);
  std::vector<int> nodes(static_cast<size_t>(m.num_nodes())),
      tets(static_cast<size_t>(m.num_tets()));
  std::iota(nodes.begin(), nodes.end(), 0);
  std::iota(tets.begin(), tets.end(), 0);
  const DofMap dofs = make_dof_map(m.num_nodes(), nodes, {});
  const SparseMatrix k = assemble_stiffness(m, cache, tets, dofs);

  Eigen::Matrix3d a;
  a << 1e-3, 2e-3, -5e-4, 3e-4, -1e-3, 7e-4, -2e-3, 4e-4, 1.5e-3;
  const Vec3 c(1e-3, -2e-3, 3e-3);
  Vector u(3 * m.num_nodes());
  for (int n = 0; n < m.num_nodes(); ++n) u.segment<3>(3 * n) = a * m.nodes[n] + c;

  // Exact constant strain in every element.
  Eigen::Matrix<double, 6, 1> eps;
  eps << a(0, 0), a(1, 1), a(2, 2), a(0, 1) + a(1, 0), a(1, 2) + a(2, 1), a(2, 0) + a(0, 2);
  for (int t = 0; t < m.num_tets(); ++t) {
    const Tet& e = m.tets[t];
    Eigen::Matrix<double, 12, 1> ue;
    for (int i = 0; i < 4; ++i) ue.segment<3>(3 * i) = u.segment<3>(3 * e[i]);
    const auto b = strain_displacement(m.nodes[e[0]], m.nodes[e[1]], m.nodes[e[2]], m.nodes[e[3]]);
    ASSERT_LE((b * ue - eps).norm(), 1e-12 * eps.norm()) << t;
  }
  // Zero interior residual: interior nodes are in equilibrium under a constant stress.
  const Vector ku = k * u;
  double boundary_max = 0, interior_max = 0;
  for (int n = 0; n < m.num_nodes(); ++n) {
    const Vec3& x = mesh.nodes[n];
    const bool interior = (x.array() > 1e-12).all() && (x.array() < g.size.array() - 1e-12).all();
    const double f = ku.segment<3>(3 * n).norm();
    (interior ? interior_max : boundary_max) = std::max(interior ? interior_max : boundary_max, f);
  }
  ASSERT_GT(boundary_max, 0);
  EXPECT_LE(interior_max, 1e-12 * boundary_max);
}

}  // namespace
}  // namespace stc
