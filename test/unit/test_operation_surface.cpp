// After cuts, the simulation's boundary surface (rebuilt from the operation part alone,
// simulation/operation_surface.hpp) is exactly the whole mesh's boundary: same oriented
// triangles, same cut flags. Thigh (its scripted stroke) and a SOFA liver (a cut service call).
#include "liver_test_scene.hpp"

#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <vector>

namespace stc {
namespace {

// Oriented triangle, rotated so its smallest node comes first, plus its cut flag.
std::vector<std::array<int, 4>> canonical(const std::vector<BoundaryTriangle>& triangles) {
  std::vector<std::array<int, 4>> out;
  for (const BoundaryTriangle& t : triangles) {
    const Tri& n = t.nodes;
    const int r = static_cast<int>(std::min_element(n.begin(), n.end()) - n.begin());
    out.push_back({n[r], n[(r + 1) % 3], n[(r + 2) % 3], t.cut ? 1 : 0});
  }
  std::sort(out.begin(), out.end());
  return out;
}

void expect_whole_boundary(const Simulation& sim) {
  const auto drawn = canonical(sim.surface().triangles);
  const auto whole = canonical(extract_boundary_surface(sim.mesh()).triangles);
  EXPECT_EQ(drawn.size(), whole.size());
  EXPECT_TRUE(drawn == whole);
}

TEST(OperationSurface, ThighStrokeKeepsTheWholeBoundary) {
  Simulation sim(make_thigh_scene());
  for (const BladePose& p : sim.scene().trajectory) sim.step(p);
  ASSERT_GT(sim.counts().cuts, 0);
  expect_whole_boundary(sim);
}

TEST(OperationSurface, LiverCutKeepsTheWholeBoundary) {
  Scene scene = testing_scenes::liver_scene("sofa_liver2.msh", false, 3, 0.25);
  const Sphere region = scene.operation_region.sphere;
  scene.scalpel.blade_length = 0.6 * region.radius;
  Simulation sim(scene);
  // A blade drawn along z through the sphere, its edge (local +x) up from a tip below centre.
  BladePose a, b;
  a.orientation = b.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitZ()));
  a.position = region.center + Vec3(0.013, -0.4 * region.radius, -0.6 * region.radius);
  b.position = region.center + Vec3(0.013, -0.4 * region.radius, 0.6 * region.radius);
  const CutOutcome out = sim.cut_along({a, b});
  ASSERT_TRUE(out.success) << out.message;
  EXPECT_GT(out.cut_faces, 0);
  expect_whole_boundary(sim);
}

}  // namespace
}  // namespace stc
