// TetFaceAdjacency (mesh/face_adjacency.hpp): after every one of hundreds of seeded random
// sweeps through the thigh's and a TetGen liver's operation part, updated from the tets each
// sweep changed alone, its boundary is the same set of triangles (nodes, winding, owner, cut
// flag) and non-manifold count as extract_boundary_surface of the operation tets, and its pieces
// the same as face_connected_pieces of those tets.
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "cutting/free_pieces.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/mesh/face_adjacency.hpp"
#include "soft_tissue_cutting/partition/partition.hpp"
#include "soft_tissue_cutting/simulation/operation_surface.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <random>
#include <tuple>

namespace stc {
namespace {

using Row = std::tuple<int, int, int, int, int, bool>;  // nodes, tet, face, cut

std::vector<Row> rows_of(const BoundarySurface& s) {
  std::vector<Row> rows;
  for (const BoundaryTriangle& t : s.triangles)
    rows.emplace_back(t.nodes[0], t.nodes[1], t.nodes[2], t.tet, t.face, t.cut);
  std::sort(rows.begin(), rows.end());
  return rows;
}

// Checks the adjacency of `members` against the from-scratch extraction.
void expect_same(const TetFaceAdjacency& adjacency, const TetMesh& mesh,
                 const std::vector<int>& members, const std::string& where) {
  BoundarySurface ref = extract_boundary_surface(tet_subset(mesh, members));
  for (BoundaryTriangle& t : ref.triangles) t.tet = members[static_cast<size_t>(t.tet)];
  const BoundarySurface got = adjacency.boundary(mesh);
  ASSERT_EQ(rows_of(got), rows_of(ref)) << where;
  EXPECT_EQ(got.non_manifold_faces, ref.non_manifold_faces) << where;
  std::vector<MeshPiece> ref_pieces = face_connected_pieces(tet_subset(mesh, members));
  for (MeshPiece& p : ref_pieces)
    for (int& t : p.tets) t = members[static_cast<size_t>(t)];
  const std::vector<MeshPiece> pieces = adjacency.pieces(mesh);
  ASSERT_EQ(pieces.size(), ref_pieces.size()) << where;
  for (size_t k = 0; k < pieces.size(); ++k) {
    EXPECT_EQ(pieces[k].tets, ref_pieces[k].tets) << where << ", piece " << k;
    EXPECT_EQ(pieces[k].nodes, ref_pieces[k].nodes) << where << ", piece " << k;
  }
}

// pieces_cut_off after an update, against the whole mesh's pieces before and after it: every
// piece it returns is one of the pieces now, and it returns every NEW piece (not one before)
// except at most one larger than `budget` (the rest of the body). It may leave the answer
// undecided (nullopt: walks that ran out before they met), and must where two new pieces are
// larger than the budget. Returns the pieces now; counts the decided answers.
std::vector<MeshPiece> expect_cut_off(TetFaceAdjacency& adjacency, const TetMesh& mesh,
                                      const std::vector<MeshPiece>& before, size_t budget,
                                      const std::string& where, int& decided) {
  const std::vector<MeshPiece> now = adjacency.pieces(mesh);
  const auto cut_off = adjacency.pieces_cut_off(mesh, budget);
  auto same = [](const MeshPiece& a, const MeshPiece& b) {
    return a.tets == b.tets && a.nodes == b.nodes;
  };
  auto in = [&](const MeshPiece& p, const std::vector<MeshPiece>& list) {
    return std::any_of(list.begin(), list.end(), [&](const MeshPiece& q) { return same(p, q); });
  };
  std::vector<const MeshPiece*> fresh, big;
  for (const MeshPiece& p : now)
    if (!in(p, before)) {
      fresh.push_back(&p);
      if (p.tets.size() > budget) big.push_back(&p);
    }
  if (!cut_off) return now;
  ++decided;
  EXPECT_LE(big.size(), 1u) << where << ": decided with two new pieces past the budget";
  for (const MeshPiece& p : *cut_off)
    EXPECT_TRUE(in(p, now)) << where << ": a piece not in pieces()";
  for (const MeshPiece* p : fresh) {
    if (p->tets.size() > budget) continue;
    EXPECT_TRUE(in(*p, *cut_off)) << where << ": new piece of " << p->tets.size()
                                  << " tets (from tet " << p->tets.front() << ") missed";
  }
  EXPECT_TRUE(std::is_sorted(
      cut_off->begin(), cut_off->end(),
      [](const MeshPiece& a, const MeshPiece& b) { return a.tets.front() < b.tets.front(); }))
      << where;
  return now;
}

// `sweeps` random blade sweeps through the scene's operation part, ending in a cut mesh with
// several pieces; returns how many sweeps changed tets.
int sweep_and_check(const Scene& scene, unsigned seed, int sweeps) {
  TetMesh mesh = scene.mesh;
  const Partition p = partition_mesh(mesh, scene.operation_region);
  std::vector<std::uint8_t> locked(mesh.nodes.size(), 0);
  for (int n : p.interface) locked[static_cast<size_t>(n)] = 1;
  CutState state = make_cut_state(mesh, locked, p.operation_tet);
  std::vector<int> members = p.operation_tets;
  TetFaceAdjacency adjacency;
  adjacency.build(mesh, members);
  adjacency.track_cut_off(true);
  expect_same(adjacency, mesh, members, "uncut");
  std::vector<MeshPiece> pieces = adjacency.pieces(mesh);
  int decided = 0;
  Vec3 lo = Vec3::Constant(1e300), hi = -lo;
  for (int t : members)
    for (int v : mesh.tets[static_cast<size_t>(t)])
      lo = lo.cwiseMin(mesh.nodes[static_cast<size_t>(v)]),
      hi = hi.cwiseMax(mesh.nodes[static_cast<size_t>(v)]);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  auto point = [&] { return Vec3(lo + (hi - lo).cwiseProduct(Vec3(u(rng), u(rng), u(rng)))); };
  const double length = 0.5 * (hi - lo).minCoeff();
  int changed = 0;
  for (int k = 0; k < sweeps; ++k) {
    BladeEdge from, to;
    from.tip = point();
    const Vec3 edge = (point() - point()).normalized() * length;
    const Vec3 move = (point() - point()).normalized() * 0.3 * length;
    from.heel = from.tip + edge;
    to.tip = from.tip + move;
    to.heel = from.heel + move;
    from.normal = to.normal = edge.cross(move).normalized();
    const CutResult r = cut_sweep(mesh, state, from, to);
    if (r.changed_tets.empty()) continue;
    ++changed;
    adjacency.update(mesh, r.changed_tets);
    for (int t : r.changed_tets)
      if (!std::binary_search(members.begin(), members.end(), t)) members.push_back(t);
    std::sort(members.begin(), members.end());
    expect_same(adjacency, mesh, members, "sweep " + std::to_string(k));
    // A budget of a tenth of part 1: the walks mostly meet within it (a sweep here cuts no
    // piece off; FollowsSweepsThatSeverPieces and CutOffPiecesAreFoundFromTheChange do).
    pieces = expect_cut_off(adjacency, mesh, pieces, members.size() / 10,
                            "sweep " + std::to_string(k), decided);
    if (::testing::Test::HasFatalFailure()) return changed;
  }
  EXPECT_GT(decided, changed / 2) << "the walks decided too rarely to be tested";
  std::printf(
      "[ adjacency] %d of %d sweeps changed tets (%d decided from the change): %d -> %zu "
      "part-1 tets, %zu pieces, %zu boundary triangles\n",
      changed, sweeps, decided, static_cast<int>(p.operation_tets.size()), members.size(),
      adjacency.pieces(mesh).size(), adjacency.boundary(mesh).triangles.size());
  return changed;
}

TEST(TetFaceAdjacency, FollowsRandomSweepsThroughTheThigh) {
  EXPECT_GE(sweep_and_check(make_thigh_scene(), 11u, 150), 40);
}

TEST(TetFaceAdjacency, FollowsRandomSweepsThroughATetgenLiver) {
  Scene s;
  MeshReadOptions options;
  options.tetgen_switches = "pq1.4/10Q";
  s.mesh = read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/sofa_liver2.obj", options);
  Vec3 lo = s.mesh.nodes[0], hi = lo;
  for (const Vec3& x : s.mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  s.operation_region.kind = OperationRegion::Kind::kSphere;
  s.operation_region.sphere = Sphere{0.5 * (lo + hi), 0.3 * (hi - lo).maxCoeff()};
  EXPECT_GE(sweep_and_check(s, 5u, 150), 40);
}

// Sweeps across the whole of a box with no interface: the first severs it in two, the second
// severs more (three pieces: one half is held together by what the cut leaves); the pieces
// follow.
TEST(TetFaceAdjacency, FollowsSweepsThatSeverPieces) {
  GeneratorParams g;
  g.size = Vec3(0.04, 0.03, 0.02);
  g.cells = {8, 6, 4};
  TetMesh mesh = make_box_mesh(g);
  std::vector<int> members(static_cast<size_t>(mesh.num_tets()));
  std::iota(members.begin(), members.end(), 0);
  std::vector<std::uint8_t> locked(mesh.nodes.size(), 0), cuttable(members.size(), 1);
  CutState state = make_cut_state(mesh, locked, cuttable);
  TetFaceAdjacency adjacency;
  adjacency.build(mesh, members);
  ASSERT_EQ(adjacency.pieces(mesh).size(), 1u);
  adjacency.track_cut_off(true);
  TetFaceAdjacency twin;  // the same updates, its walks with a budget that takes all
  twin.build(mesh, members);
  twin.track_cut_off(true);
  // A blade longer than the box, drawn through all of it: x = 0.0213, then y = 0.0137.
  const std::vector<std::array<Vec3, 2>> planes = {
      {Vec3(0.0213, -0.01, -0.01), Vec3(0.0213, 0.04, -0.01)},
      {Vec3(-0.01, 0.0137, -0.01), Vec3(0.05, 0.0137, -0.01)}};
  size_t before = 1;
  for (const auto& [tip, heel] : planes) {
    BladeEdge from, to;
    from.tip = tip;
    from.heel = heel;
    to.tip = tip + Vec3(0, 0, 0.04);
    to.heel = heel + Vec3(0, 0, 0.04);
    from.normal = to.normal = (heel - tip).cross(Vec3(0, 0, 1)).normalized();
    const CutResult r = cut_sweep(mesh, state, from, to);
    ASSERT_FALSE(r.changed_tets.empty());
    const std::vector<MeshPiece> pieces_before = adjacency.pieces(mesh);
    adjacency.update(mesh, r.changed_tets);
    twin.update(mesh, r.changed_tets);
    // Halves of the box: with a budget of 10 tets the walks from both sides of the cut run
    // out without meeting - undecided; with the whole mesh as budget each half is walked whole.
    const std::string where = "plane " + std::to_string(before);
    EXPECT_FALSE(adjacency.pieces_cut_off(mesh, 10).has_value()) << where;
    const auto all = twin.pieces_cut_off(mesh, mesh.tets.size());
    ASSERT_TRUE(all.has_value()) << where;
    for (const MeshPiece& p : adjacency.pieces(mesh)) {
      if (std::any_of(pieces_before.begin(), pieces_before.end(),
                      [&](const MeshPiece& q) { return q.tets == p.tets; }))
        continue;
      EXPECT_TRUE(
          std::any_of(all->begin(), all->end(),
                      [&](const MeshPiece& q) { return q.tets == p.tets && q.nodes == p.nodes; }))
          << where << ": a new half not walked";
    }
    for (int t : r.changed_tets)
      if (!std::binary_search(members.begin(), members.end(), t)) members.push_back(t);
    std::sort(members.begin(), members.end());
    expect_same(adjacency, mesh, members, "plane " + std::to_string(before));
    const size_t now = adjacency.pieces(mesh).size();
    EXPECT_GT(now, before);
    before = now;
  }
}

// A face of more than two tets (a non-manifold input) joins all of them into one piece, as
// face_connected_pieces does, and stops doing so once a tet is rewritten off it.
TEST(TetFaceAdjacency, FaceOfThreeTetsJoinsThemUntilOneLeaves) {
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0),     Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1),
                Vec3(0.2, 0.2, 1), Vec3(3, 3, 3), Vec3(4, 3, 3), Vec3(3, 4, 3)};
  mesh.tets = {{0, 1, 2, 3}, {0, 2, 1, 4}, {0, 1, 2, 5}};
  std::vector<int> members = {0, 1, 2};
  TetFaceAdjacency adjacency;
  adjacency.build(mesh, members);
  adjacency.track_cut_off(true);
  expect_same(adjacency, mesh, members, "three tets on one face");
  ASSERT_EQ(adjacency.pieces(mesh).size(), 1u);
  mesh.tets[2] = {6, 7, 8, 5};  // off the shared face: two tets share it now
  adjacency.update(mesh, {2});
  expect_same(adjacency, mesh, members, "one tet rewritten off it");
  EXPECT_EQ(adjacency.pieces(mesh).size(), 2u);
  // Walked from the change: with a budget of one tet, {0, 1} is the rest and {2} is cut off.
  const auto cut_off = adjacency.pieces_cut_off(mesh, 1);
  ASSERT_TRUE(cut_off.has_value());
  ASSERT_EQ(cut_off->size(), 1u);
  EXPECT_EQ(cut_off->front().tets, std::vector<int>({2}));
  EXPECT_EQ(cut_off->front().nodes, std::vector<int>({5, 6, 7, 8}));
  mesh.tets[2] = {0, 1, 2, 5};  // and back
  adjacency.update(mesh, {2});
  expect_same(adjacency, mesh, members, "and back");
  EXPECT_EQ(adjacency.pieces(mesh).size(), 1u);
  // The crowded face joins all three in the walk too.
  const auto joined = adjacency.pieces_cut_off(mesh, 5);
  ASSERT_TRUE(joined.has_value());
  ASSERT_EQ(joined->size(), 1u);
  EXPECT_EQ(joined->front().tets, std::vector<int>({0, 1, 2}));
}

// A slab cut off a box (the tets with centroid x < 6 mm rewritten onto copies of the nodes
// they share with the rest, as separation does): walked from the change with a budget of a
// quarter of the mesh, the slab is found whole and the rest is one walk that ran out; with
// a budget of 10 tets both run out apart (undecided); with the whole mesh, both are found.
TEST(TetFaceAdjacency, CutOffPiecesAreFoundFromTheChange) {
  GeneratorParams g;
  g.size = Vec3(0.04, 0.03, 0.02);
  g.cells = {8, 6, 4};
  const TetMesh uncut = make_box_mesh(g);
  std::vector<int> members(static_cast<size_t>(uncut.num_tets()));
  std::iota(members.begin(), members.end(), 0);
  TetMesh mesh = uncut;
  std::vector<int> slab, copy_of(mesh.nodes.size(), -1);
  std::vector<std::uint8_t> in_rest(mesh.nodes.size(), 0);
  auto centroid_x = [&](const Tet& t) {
    double x = 0;
    for (int v : t) x += 0.25 * mesh.nodes[static_cast<size_t>(v)].x();
    return x;
  };
  for (int t = 0; t < mesh.num_tets(); ++t) {
    if (centroid_x(mesh.tets[static_cast<size_t>(t)]) < 0.006)
      slab.push_back(t);
    else
      for (int v : mesh.tets[static_cast<size_t>(t)]) in_rest[static_cast<size_t>(v)] = 1;
  }
  ASSERT_FALSE(slab.empty());
  for (int t : slab)
    for (int& v : mesh.tets[static_cast<size_t>(t)]) {
      if (!in_rest[static_cast<size_t>(v)]) continue;
      if (copy_of[static_cast<size_t>(v)] < 0) {
        copy_of[static_cast<size_t>(v)] = mesh.num_nodes();
        mesh.nodes.push_back(mesh.nodes[static_cast<size_t>(v)]);
      }
      v = copy_of[static_cast<size_t>(v)];
    }
  const size_t quarter = members.size() / 4;
  for (const size_t budget : {quarter, size_t{10}, members.size()}) {
    TetFaceAdjacency adjacency;
    adjacency.build(uncut, members);
    adjacency.update(mesh, slab);
    EXPECT_FALSE(adjacency.pieces_cut_off(mesh, budget).has_value());  // not tracking: undecided
    adjacency.build(uncut, members);
    adjacency.track_cut_off(true);
    adjacency.update(mesh, slab);
    const std::vector<MeshPiece> pieces = adjacency.pieces(mesh);
    ASSERT_EQ(pieces.size(), 2u);
    const MeshPiece& slab_piece =
        pieces[0].tets.size() < pieces[1].tets.size() ? pieces[0] : pieces[1];
    EXPECT_EQ(slab_piece.tets, slab);
    const auto cut_off = adjacency.pieces_cut_off(mesh, budget);
    if (budget == 10) {
      EXPECT_FALSE(cut_off.has_value());
      continue;
    }
    ASSERT_TRUE(cut_off.has_value()) << "budget " << budget;
    ASSERT_EQ(cut_off->size(), budget == quarter ? 1u : 2u) << "budget " << budget;
    const MeshPiece& found =
        budget == quarter ? cut_off->front()
                          : (*cut_off)[slab_piece.tets.front() == pieces[0].tets.front() ? 0 : 1];
    EXPECT_EQ(found.tets, slab_piece.tets);
    EXPECT_EQ(found.nodes, slab_piece.nodes);
    // Nothing changed since: the next call walks nothing and finds nothing.
    const auto again = adjacency.pieces_cut_off(mesh, budget);
    ASSERT_TRUE(again.has_value());
    EXPECT_TRUE(again->empty());
  }
}

}  // namespace
}  // namespace stc
