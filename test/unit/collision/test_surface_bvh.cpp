// collision/surface_bvh: segment candidates against brute force, ray-parity point-in-tissue.
#include "soft_tissue_cutting/collision/surface_bvh.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"

#include "common/meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace stc {
namespace {

using test::cube_mesh;

TEST(CollisionBvh, SegmentCandidatesMatchBruteForceOnTheDeformedThigh) {
  const Scene scene = make_thigh_scene();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.07, 0.07), z(0.0, 0.096), small(-1e-3, 1e-3);
  std::vector<Vec3> displacement(scene.mesh.nodes.size());
  for (Vec3& d : displacement) d = Vec3(small(rng), small(rng), small(rng));
  SurfaceBvh bvh;
  bvh.build(scene.mesh, {}, {});
  bvh.refit(scene.mesh, displacement);  // refit must equal a fresh build on moved nodes
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a(u(rng), u(rng), z(rng)), b = a + Vec3(small(rng), small(rng), small(rng)) * 20;
    std::vector<int> fast = bvh.near_segment(a, b, 0);
    std::sort(fast.begin(), fast.end());
    // Brute force: every triangle whose exact crossing test passes must be a candidate.
    for (size_t t = 0; t < bvh.surface().triangles.size(); ++t) {
      const Tri& n = bvh.surface().triangles[t].nodes;
      double s;
      if (segment_crosses_triangle(a, b, bvh.position(n[0]), bvh.position(n[1]), bvh.position(n[2]),
                                   s)) {
        EXPECT_TRUE(std::binary_search(fast.begin(), fast.end(), static_cast<int>(t)));
      }
    }
  }
}

TEST(CollisionBvh, PointInTissueByRayParity) {
  const Scene scene = make_thigh_scene();
  SurfaceBvh bvh;
  bvh.build(scene.mesh, {}, {});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.07, 0.07), z(-0.01, 0.106);
  int checked = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Vec3 p(u(rng), u(rng), z(rng));
    const double r = std::hypot(p.x(), p.y());
    // Away from the polygonal walls (chord error < 2 mm) the answer is the tube's.
    if (std::abs(r - 0.015) < 2e-3 || std::abs(r - 0.06) < 3e-3 || std::abs(p.z()) < 1e-3 ||
        std::abs(p.z() - 0.096) < 1e-3)
      continue;
    const bool inside = r > 0.015 && r < 0.06 && p.z() > 0 && p.z() < 0.096;
    EXPECT_EQ(bvh.contains(p), inside) << p.transpose();
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

}  // namespace
}  // namespace stc
