// config/scenes/liver_organ.yaml, the organ-scale scene of the bench summary: a TetGen liver
// of >= 50k tets at anatomical size, resting on its fixed underside under gravity, a <= 2 cm
// operation sphere at its top, and a scripted scalpel that presses, yields and cuts.
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <gtest/gtest.h>

namespace stc {
namespace {

const std::string kScene =
    std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/liver_organ.yaml";

TEST(OrganScene, LiverOrganIsOrganScale) {
  const Scene s = load_scene(kScene);
  EXPECT_GE(s.mesh.num_tets(), 50000);
  Vec3 lo = s.mesh.nodes[0], hi = lo;
  for (const Vec3& x : s.mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  EXPECT_GE((hi - lo).maxCoeff(), 0.10);  // m
  EXPECT_LE((hi - lo).maxCoeff(), 0.20);
  EXPECT_LT(s.gravity.y(), -9.0);
  ASSERT_EQ(s.operation_region.kind, OperationRegion::Kind::kSphere);
  EXPECT_LE(s.operation_region.sphere.radius, 0.02);
  EXPECT_GE(s.operation_region.sphere.center.y(), hi.y() - 0.01);  // at the top
  // Fixed: the underside only.
  int fixed = 0;
  for (const NodeSelector& f : s.fixed)
    for (int n : f.select(s.mesh)) {
      ++fixed;
      EXPECT_LE(s.mesh.nodes[n].y(), lo.y() + 0.035);
    }
  EXPECT_GT(fixed, 0);
  // The cut: the blade is drawn 3 cm.
  double travel = 0;
  for (size_t i = 1; i < s.trajectory.size(); ++i)
    travel =
        std::max(travel, std::abs(s.trajectory[i].position.x() - s.trajectory[i - 1].position.x()));
  EXPECT_NEAR(travel, 0.03, 1e-9);
}

TEST(OrganScene, LiverOrganPressesAndCuts) {
  const Scene s = load_scene(kScene);
  Simulation sim(s);
  // The first two segments at 1 mm per step (press, yield), then 5 mm of the cut.
  const auto& p = s.trajectory;
  ASSERT_GE(p.size(), 3u);
  bool pressed = false;
  int cuts = 0;
  for (size_t i = 0; i + 1 < 3; ++i) {
    const int k = static_cast<int>(std::ceil((p[i + 1].position - p[i].position).norm() / 1e-3));
    for (int j = 0; j < (i == 1 ? 5 : k); ++j) {
      BladePose b = p[i];
      b.position =
          p[i].position + (static_cast<double>(j) / k) * (p[i + 1].position - p[i].position);
      const StepStats st = sim.step(b);
      ASSERT_TRUE(st.converged);
      pressed |= st.in_contact;
      cuts += st.cutting;
    }
  }
  EXPECT_TRUE(pressed);
  EXPECT_GT(cuts, 0);
  EXPECT_GT(sim.counts().tets, s.mesh.num_tets());
}

}  // namespace
}  // namespace stc
