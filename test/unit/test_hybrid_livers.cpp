// Hybrid condensed model vs full model on the SOFA livers (irregular meshes, worst dihedral
// 6 degrees): operation regions none / all / sphere, gravity and a point load, plus the
// surface recovery u_S before any interior recovery. <= 1e-9 relative.
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include "liver_test_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace stc {
namespace {

// One loaded node at the top, gravity, an operation sphere of 0.3 x the extent around it.
Scene liver(const std::string& file, OperationRegion::Kind kind) {
  return testing_scenes::liver_scene(file, true, 1, 0.3, kind);
}

double max_error(const Vector& u, const Vector& ref, const std::vector<int>& nodes) {
  double scale = 0, err = 0;
  for (Eigen::Index n = 0; n < ref.size() / 3; ++n)
    scale = std::max(scale, ref.segment<3>(3 * n).norm());
  for (int n : nodes) err = std::max(err, (u.segment<3>(3 * n) - ref.segment<3>(3 * n)).norm());
  return err / scale;
}

struct Case {
  const char* file;
  OperationRegion::Kind kind;
  const char* name;
};
class HybridLiver : public ::testing::TestWithParam<Case> {};

TEST_P(HybridLiver, EqualsFullModel) {
  const Case c = GetParam();
  const Scene s = liver(c.file, c.kind);
  const FullModel full = assemble_full_model(s);
  Vector x;
  solve_direct(full.K, full.f, x);
  Vector ref = Vector::Zero(3 * s.mesh.num_nodes());
  scatter(x, full.dofs, ref);

  HybridModel h(s);
  h.set_cg_settings(CgSettings{1e-12, 50000});  // liver2 `all` stalls at ~1.2e-13 (rounding)
  const CgResult r = h.solve();
  EXPECT_TRUE(r.converged) << r.iterations << " iterations, residual " << r.residual;
  const Partition& p = h.partition();
  std::vector<int> part1 = p.operation;
  part1.insert(part1.end(), p.interface.begin(), p.interface.end());
  const double e_part1 = max_error(h.displacement(), ref, part1);
  const double e_surface = max_error(h.displacement(), ref, p.surface);  // c_S + R u_I
  h.recover_interior();
  std::vector<int> all(static_cast<size_t>(s.mesh.num_nodes()));
  for (int i = 0; i < s.mesh.num_nodes(); ++i) all[static_cast<size_t>(i)] = i;
  const double e_all = max_error(h.displacement(), ref, all);
  EXPECT_LE(e_part1, 1e-9);
  EXPECT_LE(e_surface, 1e-9);
  EXPECT_LE(e_all, 1e-9);
  const HybridModelCounts n = h.counts();
  std::printf(
      "[ hybrid   ] %-14s %-6s O=%d I=%d S=%d Q=%d dof=%d cg=%d: O+I %.2e, S %.2e, all %.2e\n",
      c.file, c.name, n.nodes_operation, n.nodes_interface, n.nodes_surface_condensed,
      n.nodes_interior_condensed, n.dof_operation, r.iterations, e_part1, e_surface, e_all);
}

INSTANTIATE_TEST_SUITE_P(
    Livers, HybridLiver,
    ::testing::Values(Case{"sofa_liver.msh", OperationRegion::Kind::kSphere, "sphere"},
                      Case{"sofa_liver.msh", OperationRegion::Kind::kAll, "all"},
                      Case{"sofa_liver.msh", OperationRegion::Kind::kNone, "none"},
                      Case{"sofa_liver2.msh", OperationRegion::Kind::kSphere, "sphere"},
                      Case{"sofa_liver2.msh", OperationRegion::Kind::kAll, "all"},
                      Case{"sofa_liver2.msh", OperationRegion::Kind::kNone, "none"}),
    [](const auto& info) {
      return std::string(info.param.file[10] == '2' ? "liver2_" : "liver_") + info.param.name;
    });

}  // namespace
}  // namespace stc
