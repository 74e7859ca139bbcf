// Collision (issue 4): the surface BVH against brute force, ray-parity point-in-tissue, and
// blade contact on a box.
#include "soft_tissue_cutting/collision/contact.hpp"
#include "soft_tissue_cutting/collision/surface_bvh.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"

#include "test_meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace stc {
namespace {

using testing_meshes::cube_mesh;

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

TEST(CollisionContact, EdgeThroughTheTopFaceHoldsThatTrianglesNodes) {
  const TetMesh mesh = cube_mesh();
  SurfaceBvh bvh;
  bvh.build(mesh, {}, {});
  // A vertical edge poking 3 mm into the top face z = 4 cm.
  BladeEdge edge;
  edge.tip = Vec3(0.013, 0.012, 0.037);
  edge.heel = Vec3(0.013, 0.012, 0.06);
  const BladeContact contact = blade_contact(bvh, mesh, edge, 1e-6);
  ASSERT_EQ(contact.crossed_triangles.size(), 1u);
  EXPECT_EQ(contact.nodes.size(), 3u);
  for (const ContactNode& c : contact.nodes) {
    const Vec3 held = mesh.nodes[c.node] + c.imposed_displacement;
    EXPECT_NEAR((held - closest_point_on_segment(edge.tip, edge.heel, held)).norm(), 0, 1e-15);
    EXPECT_NEAR(held.x(), 0.013, 1e-15);
    EXPECT_NEAR(held.y(), 0.012, 1e-15);
    EXPECT_NEAR(mesh.nodes[c.node].z(), 0.04, 1e-15);
    EXPECT_GT(c.depth, 0);
  }
  // Once the nodes sit on the blade, they stay held (within the touch distance) and only
  // they: triangles around them are not pulled in.
  std::vector<Vec3> u(mesh.nodes.size(), Vec3::Zero());
  for (const ContactNode& c : contact.nodes) u[c.node] = c.imposed_displacement;
  bvh.refit(mesh, u);
  const BladeContact held = blade_contact(bvh, mesh, edge, 1e-6);
  ASSERT_EQ(held.nodes.size(), 3u);
  for (size_t k = 0; k < 3; ++k) EXPECT_EQ(held.nodes[k].node, contact.nodes[k].node);
}

TEST(CollisionContact, BladeOutsideTouchesNothing) {
  const TetMesh mesh = cube_mesh();
  SurfaceBvh bvh;
  bvh.build(mesh, {}, {});
  BladeEdge edge;
  edge.tip = Vec3(0.02, 0.02, 0.045);
  edge.heel = Vec3(0.02, 0.02, 0.06);
  EXPECT_TRUE(blade_contact(bvh, mesh, edge, 1e-6).nodes.empty());
  EXPECT_FALSE(bvh.contains(edge.tip));
  EXPECT_TRUE(bvh.contains(Vec3(0.02, 0.02, 0.035)));
}

}  // namespace
}  // namespace stc
