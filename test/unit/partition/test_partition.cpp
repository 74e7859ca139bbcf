// partition/: the operation part by centroid and the node sets O, I, S, Q (docs/DESIGN.md
// section 3), checked against definitions recomputed here from the mesh alone: the cube's
// boundary nodes are those on its six faces, not what extract_boundary_surface says.
#include "soft_tissue_cutting/partition/partition.hpp"

#include "common/meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace stc {
namespace {

constexpr double kSide = 0.04;  // test::cube_mesh(): 4 cm, 1 cm cells

bool on_cube_face(const Vec3& p) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(p[k]) < 1e-12 || std::abs(p[k] - kSide) < 1e-12) return true;
  return false;
}

Vec3 centroid(const TetMesh& mesh, int t) {
  const Tet& e = mesh.tets[static_cast<size_t>(t)];
  return 0.25 * (mesh.nodes[e[0]] + mesh.nodes[e[1]] + mesh.nodes[e[2]] + mesh.nodes[e[3]]);
}

OperationRegion top_sphere() {
  OperationRegion r;
  r.kind = OperationRegion::Kind::kSphere;
  r.sphere.center = Vec3(0.02, 0.02, kSide);
  r.sphere.radius = 0.018;
  return r;
}

TEST(Partition, SphereRegionMatchesTheDefinitionsOfEverySet) {
  const TetMesh mesh = test::cube_mesh();
  const OperationRegion region = top_sphere();
  const Partition p = partition_mesh(mesh, region);

  // Part 1 = tets whose centroid is in the sphere, and the tet lists agree with the flags.
  std::vector<int> expected_op, expected_cond;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const bool in = (centroid(mesh, t) - region.sphere.center).norm() <= region.sphere.radius;
    EXPECT_EQ(p.operation_tet[static_cast<size_t>(t)], in ? 1 : 0) << "tet " << t;
    (in ? expected_op : expected_cond).push_back(t);
  }
  EXPECT_EQ(p.operation_tets, expected_op);
  EXPECT_EQ(p.condensed_tets, expected_cond);
  ASSERT_GT(expected_op.size(), 10u);
  ASSERT_GT(expected_cond.size(), expected_op.size());

  // O: only part-1 tets; I: both parts; S: only part 2 and on the cube's faces; Q: only part 2,
  // inside.
  std::vector<int> used(static_cast<size_t>(mesh.num_nodes()), 0);
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int n : mesh.tets[static_cast<size_t>(t)])
      used[static_cast<size_t>(n)] |= p.operation_tet[static_cast<size_t>(t)] ? 1 : 2;
  std::vector<int> o, i, s, q;
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const int u = used[static_cast<size_t>(n)];
    if (u == 1) o.push_back(n);
    if (u == 3) i.push_back(n);
    if (u == 2) (on_cube_face(mesh.nodes[static_cast<size_t>(n)]) ? s : q).push_back(n);
  }
  EXPECT_EQ(p.operation, o);
  EXPECT_EQ(p.interface, i);
  EXPECT_EQ(p.surface, s);
  EXPECT_EQ(p.interior, q);
  EXPECT_EQ(o.size() + i.size() + s.size() + q.size(), static_cast<size_t>(mesh.num_nodes()));
  EXPECT_FALSE(o.empty());
  EXPECT_FALSE(i.empty());
  EXPECT_FALSE(q.empty());
  for (int n : o) EXPECT_EQ(p.node_set[static_cast<size_t>(n)], NodeSet::kOperation);
  for (int n : i) EXPECT_EQ(p.node_set[static_cast<size_t>(n)], NodeSet::kInterface);
  for (int n : s) EXPECT_EQ(p.node_set[static_cast<size_t>(n)], NodeSet::kSurface);
  for (int n : q) EXPECT_EQ(p.node_set[static_cast<size_t>(n)], NodeSet::kInterior);
}

TEST(Partition, AllAndNoneCondenseNothingAndEverything) {
  const TetMesh mesh = test::cube_mesh();
  OperationRegion all;
  all.kind = OperationRegion::Kind::kAll;
  const Partition pa = partition_mesh(mesh, all);
  EXPECT_TRUE(pa.everything_operation());
  EXPECT_EQ(pa.operation.size(), static_cast<size_t>(mesh.num_nodes()));
  EXPECT_TRUE(pa.interface.empty() && pa.surface.empty() && pa.interior.empty());

  OperationRegion none;
  none.kind = OperationRegion::Kind::kNone;
  const Partition pn = partition_mesh(mesh, none);
  EXPECT_TRUE(pn.nothing_operation());
  EXPECT_TRUE(pn.operation.empty() && pn.interface.empty());
  EXPECT_EQ(pn.surface.size(), 98u);  // 5^3 - 3^3 nodes on the faces of a 4x4x4-cell cube
  EXPECT_EQ(pn.interior.size(), 27u);
}

TEST(Partition, OperationChangeAppendsToPartOneAndRefusesToReachPartTwo) {
  TetMesh mesh = test::cube_mesh();
  Partition p = partition_mesh(mesh, top_sphere());
  const Partition before = p;

  // A cut-like change: part-1 tet t0 gets a fresh copy of one of its operation nodes, and an
  // appended tet uses the old node (both stay part 1).
  int t0 = -1, node = -1;
  for (int t : p.operation_tets) {
    for (int n : mesh.tets[static_cast<size_t>(t)])
      if (p.node_set[static_cast<size_t>(n)] == NodeSet::kOperation) node = n;
    if (node >= 0) {
      t0 = t;
      break;
    }
  }
  ASSERT_GE(t0, 0);
  mesh.nodes.push_back(mesh.nodes[static_cast<size_t>(node)]);
  const int copy = mesh.num_nodes() - 1;
  Tet appended = mesh.tets[static_cast<size_t>(t0)];
  for (int& n : mesh.tets[static_cast<size_t>(t0)])
    if (n == node) n = copy;
  mesh.tets.push_back(appended);
  const int t_new = mesh.num_tets() - 1;
  ASSERT_TRUE(update_partition_for_operation_change(mesh, {t0, t_new}, p));
  EXPECT_EQ(p.operation_tet.size(), static_cast<size_t>(mesh.num_tets()));
  EXPECT_EQ(p.operation_tet[static_cast<size_t>(t_new)], 1);
  EXPECT_EQ(p.operation_tets.back(), t_new);
  EXPECT_EQ(p.node_set[static_cast<size_t>(copy)], NodeSet::kOperation);
  EXPECT_TRUE(std::binary_search(p.operation.begin(), p.operation.end(), copy));
  // Part 2 untouched: I, S, Q as before.
  EXPECT_EQ(p.interface, before.interface);
  EXPECT_EQ(p.surface, before.surface);
  EXPECT_EQ(p.interior, before.interior);

  // Changing a part-2 tet is refused.
  Partition refused = before;
  EXPECT_FALSE(
      update_partition_for_operation_change(mesh, {before.condensed_tets.front()}, refused));
  // ... and leaves the partition as it was (the model updates its own in place).
  EXPECT_EQ(refused.operation_tet, before.operation_tet);
  EXPECT_EQ(refused.node_set, before.node_set);
  EXPECT_EQ(refused.operation, before.operation);
  EXPECT_EQ(refused.operation_tets, before.operation_tets);
  // A part-1 tet rewritten onto a node of S (the change reaches part 2): refused, unchanged.
  Partition onto_surface = p;
  const Partition kept = onto_surface;
  TetMesh reaching = mesh;
  reaching.tets[static_cast<size_t>(t0)][0] = before.surface.front();
  EXPECT_FALSE(update_partition_for_operation_change(reaching, {t0}, onto_surface));
  EXPECT_EQ(onto_surface.operation_tet, kept.operation_tet);
  EXPECT_EQ(onto_surface.node_set, kept.node_set);
  EXPECT_EQ(onto_surface.operation, kept.operation);
  EXPECT_EQ(onto_surface.operation_tets, kept.operation_tets);
}

}  // namespace
}  // namespace stc
