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

// Every triangle whose deformed box meets segment [a, b]'s box padded by `margin` is among
// bvh.near_segment's candidates (the trees may add more: a refitted tree's leaves differ from
// a fresh build's).
::testing::AssertionResult box_candidates_found(const SurfaceBvh& bvh, const Vec3& a, const Vec3& b,
                                                double margin) {
  std::vector<int> found = bvh.near_segment(a, b, margin);
  std::sort(found.begin(), found.end());
  Box3 query(a);
  query.extend(b);
  query.min().array() -= margin;
  query.max().array() += margin;
  for (size_t t = 0; t < bvh.surface().triangles.size(); ++t) {
    const Tri& n = bvh.surface().triangles[t].nodes;
    Box3 box(bvh.position(n[0]));
    box.extend(bvh.position(n[1]));
    box.extend(bvh.position(n[2]));
    if (box.intersects(query) &&
        !std::binary_search(found.begin(), found.end(), static_cast<int>(t)))
      return ::testing::AssertionFailure()
             << "triangle " << t << " missing for segment " << a.transpose();
  }
  return ::testing::AssertionSuccess();
}

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

// Two trees (operation triangles, the rest): every triangle whose box meets the query's is a
// candidate (candidates are whole leaves, so the sets themselves depend on the trees), and
// point-in-tissue answers equal one tree's over every triangle - after a build, after a refit
// on moved nodes, and after a second build that keeps the other triangles' tree (their set
// unchanged): the path every cut takes.
// A cut's rebuild from the operation part alone (rebuild_after: the other tree's leading
// triangles kept, neither copied nor compared) answers exactly as a build of the whole surface
// does: same triangles, same operation flags, same candidates, same inside answers. A tail with
// a triangle that is not the operation part's is indexed whole, as a build.
TEST(CollisionBvh, RebuildAfterTheKeptTrianglesAnswersLikeABuild) {
  const Scene scene = make_thigh_scene();
  std::vector<std::uint8_t> operation(scene.mesh.tets.size(), 0);
  for (size_t t = 0; t < scene.mesh.tets.size(); ++t) {
    Vec3 c = Vec3::Zero();
    for (int v : scene.mesh.tets[t]) c += 0.25 * scene.mesh.nodes[v];
    operation[t] = c.x() > 0.03;
  }
  BoundarySurface others, tail;
  for (const BoundaryTriangle& t : extract_boundary_surface(scene.mesh).triangles)
    (operation[t.tet] ? tail : others).triangles.push_back(t);
  const size_t kept = others.triangles.size();
  ASSERT_GT(kept, 0u);
  ASSERT_GT(tail.triangles.size(), 10u);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-0.07, 0.07), z(-0.01, 0.106), small(-2e-3, 2e-3);
  std::vector<Vec3> moved(scene.mesh.nodes.size());
  for (Vec3& d : moved) d = Vec3(small(rng), small(rng), small(rng));
  const auto whole = [&](const BoundarySurface& t) {
    BoundarySurface s = others;
    s.triangles.insert(s.triangles.end(), t.triangles.begin(), t.triangles.end());
    return s;
  };
  SurfaceBvh fast;
  fast.build(whole(tail), scene.mesh, operation, {});
  // The operation part changed: some triangles gone, the rest in another order; nodes moved.
  BoundarySurface changed;
  changed.triangles.assign(tail.triangles.rbegin(), tail.triangles.rend() - 7);
  const auto same_as_build = [&](const BoundarySurface& t, const char* when) {
    fast.rebuild_after(kept, t, scene.mesh, operation, moved);
    SurfaceBvh ref;
    ref.build(whole(t), scene.mesh, operation, moved);
    ASSERT_EQ(fast.surface().triangles.size(), ref.surface().triangles.size()) << when;
    for (size_t i = 0; i < ref.surface().triangles.size(); ++i) {
      const Tri& n = ref.surface().triangles[i].nodes;
      ASSERT_EQ(fast.surface().triangles[i].nodes, n) << when;
      ASSERT_EQ(fast.is_operation(static_cast<int>(i)), ref.is_operation(static_cast<int>(i)))
          << when << ", triangle " << i;
      for (int v : n) ASSERT_EQ(fast.position(v), ref.position(v)) << when;
    }
    for (int trial = 0; trial < 300; ++trial) {
      const Vec3 a(u(rng), u(rng), z(rng)), b = a + Vec3(small(rng), small(rng), small(rng)) * 10;
      ASSERT_TRUE(box_candidates_found(fast, a, b, 1e-3)) << when;
      ASSERT_EQ(fast.contains(a), ref.contains(a)) << when << ", point " << a.transpose();
    }
  };
  same_as_build(changed, "the operation part rebuilt");
  for (Vec3& d : moved) d += Vec3(small(rng), small(rng), small(rng));
  same_as_build(tail, "rebuilt again after the nodes moved");
  BoundarySurface with_other = changed;
  with_other.triangles.push_back(others.triangles.front());  // not the operation part's
  same_as_build(with_other, "a tail triangle of the other part");
  same_as_build(changed, "after the whole indexing");
}

TEST(CollisionBvh, OperationAndOtherTreesAnswerLikeOneTree) {
  const Scene scene = make_thigh_scene();
  std::vector<std::uint8_t> operation(scene.mesh.tets.size(), 0);
  for (size_t t = 0; t < scene.mesh.tets.size(); ++t) {
    Vec3 c = Vec3::Zero();
    for (int v : scene.mesh.tets[t]) c += 0.25 * scene.mesh.nodes[v];
    operation[t] = c.x() > 0.03;  // the +x side of the tube
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.07, 0.07), z(-0.01, 0.106), small(-2e-3, 2e-3);
  std::vector<Vec3> moved(scene.mesh.nodes.size());
  for (Vec3& d : moved) d = Vec3(small(rng), small(rng), small(rng));
  SurfaceBvh split, one;
  split.build(scene.mesh, operation, {});
  one.build(scene.mesh, {}, {});
  int operation_triangles = 0;
  for (size_t t = 0; t < split.surface().triangles.size(); ++t)
    operation_triangles += split.is_operation(static_cast<int>(t));
  ASSERT_GT(operation_triangles, 0);
  ASSERT_LT(operation_triangles, static_cast<int>(split.surface().triangles.size()));
  auto same_answers = [&](const char* when) {
    for (int trial = 0; trial < 300; ++trial) {
      const Vec3 a(u(rng), u(rng), z(rng)), b = a + Vec3(small(rng), small(rng), small(rng)) * 10;
      ASSERT_TRUE(box_candidates_found(split, a, b, 1e-3)) << when;
      ASSERT_EQ(split.contains(a), one.contains(a)) << when << ", point " << a.transpose();
    }
  };
  same_answers("after the build");
  split.refit(scene.mesh, moved);
  one.refit(scene.mesh, moved);
  same_answers("after a refit");
  split.build(scene.mesh, operation, moved);  // the other triangles' tree kept, refitted
  one.build(scene.mesh, {}, moved);
  same_answers("after a second build");
  // A step's refit: only the nodes near the operation part move (its interface), so the other
  // tree refits the few triangles on them, their leaves and those leaves' ancestors.
  int near = 0;
  for (size_t i = 0; i < moved.size(); ++i)
    if (std::abs(scene.mesh.nodes[i].x() - 0.03) < 6e-3) {
      moved[i] += Vec3(3e-3, -2e-3, 1e-3);
      ++near;
    }
  ASSERT_GT(near, 0);
  split.refit(scene.mesh, moved);
  one.refit(scene.mesh, moved);
  same_answers("after a refit that moved a few nodes");
  // A cut's rebuild (the operation tree anew, the other one kept): its triangles on the nodes
  // that moved since the refit are refitted, and only those.
  for (size_t i = 0; i < moved.size(); ++i)
    if (std::abs(scene.mesh.nodes[i].x() - 0.03) < 6e-3) moved[i] -= Vec3(1e-3, 4e-3, -2e-3);
  split.build(scene.mesh, operation, moved);
  one.build(scene.mesh, {}, moved);
  same_answers("after a build that moved a few nodes");
  // The model's displacement as one vector (3 per node), as a step refits from it.
  Eigen::VectorXd flat(3 * static_cast<Eigen::Index>(moved.size()));
  for (size_t i = 0; i < moved.size(); ++i) {
    if (std::abs(scene.mesh.nodes[i].x() - 0.03) < 6e-3) moved[i] += Vec3(-2e-3, 1e-3, 3e-3);
    flat.segment<3>(3 * static_cast<Eigen::Index>(i)) = moved[i];
  }
  split.refit(scene.mesh, flat);
  one.refit(scene.mesh, moved);
  same_answers("after a refit from one displacement vector");
}

}  // namespace
}  // namespace stc
