// Cut insertion, the special cases: partial cuts that continue, cuts exactly through nodes,
// along edges and along faces, re-cutting, severing, and locked (interface) nodes.
#include "common/cut_measures.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "cutting/free_pieces.hpp"
#include "soft_tissue_cutting/assembly/element_cache.hpp"
#include "soft_tissue_cutting/assembly/global_assembly.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/solve/linear_solver.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

namespace stc {
using test::closed_cut_faces;
using test::open_cut_area;
namespace {

constexpr double kSide = 0.04;  // 4 cm cube of 1 cm cells

TetMesh cube_mesh() {
  GeneratorParams g;
  g.size = Vec3(kSide, kSide, kSide);
  g.cells = {4, 4, 4};
  return make_box_mesh(g);
}

// The blade edge spans z from below to above the cube at (x, y); moved between two such
// edges it sweeps the vertical plane through their footprints.
BladeEdge edge_at(double x, double y) {
  BladeEdge e;
  e.tip = Vec3(x, y, -0.01);
  e.heel = Vec3(x, y, kSide + 0.01);
  return e;
}

struct Cube {
  TetMesh mesh = cube_mesh();
  CutState state;
  double v0 = 0;
  Cube(std::vector<std::uint8_t> locked = {}, std::vector<std::uint8_t> cuttable = {}) {
    state = make_cut_state(mesh, std::move(locked), std::move(cuttable));
    v0 = total_volume(mesh);
  }
  CutResult sweep(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
    return cut_sweep(mesh, state, edge_at(from.x(), from.y()), edge_at(to.x(), to.y()));
  }
  void expect_invariants() const {
    InvariantLimits limits;
    limits.initial_volume = v0;
    for (const auto& v : check_cut_invariants(mesh, state.origin_volume, limits))
      ADD_FAILURE() << v;
  }
};

TEST(CutCases, PartialCutStaysClosedAtTheFrontThenContinues) {
  Cube cube;
  // Stop at y = 2 cm (a node plane, so the opened area is exact).
  cube.sweep({0.025, -0.01}, {0.025, 0.02});
  cube.expect_invariants();
  EXPECT_EQ(mesh_pieces(cube.mesh).size(), 1u);
  EXPECT_NEAR(open_cut_area(cube.mesh), 2 * 0.02 * kSide, 1e-9);
  cube.sweep({0.025, 0.02}, {0.025, 0.05});
  cube.expect_invariants();
  EXPECT_EQ(mesh_pieces(cube.mesh).size(), 2u);
  EXPECT_NEAR(open_cut_area(cube.mesh), 2 * kSide * kSide, 1e-9);
  EXPECT_NEAR(total_volume(cube.mesh), cube.v0, 1e-12 * cube.v0);
}

TEST(CutCases, FrontBetweenNodePlanesLeavesClosedMarksThatOpenLater) {
  Cube cube;
  cube.sweep({0.025, -0.01}, {0.025, 0.015});
  cube.expect_invariants();
  const double partial = open_cut_area(cube.mesh);
  // The opened part ends within one cell of the blade's stop.
  EXPECT_GT(partial, 2 * 0.005 * kSide);
  EXPECT_LT(partial, 2 * 0.025 * kSide);
  cube.sweep({0.025, 0.015}, {0.025, 0.05});
  cube.expect_invariants();
  EXPECT_NEAR(open_cut_area(cube.mesh), 2 * kSide * kSide, 1e-9);
  EXPECT_EQ(closed_cut_faces(cube.mesh), 0);
}

TEST(CutCases, AlongFacesOfTheKuhnSplitSplitsNothing) {
  // x = y is a union of tet faces in every Kuhn-split cell it crosses.
  Cube cube;
  const int tets0 = cube.mesh.num_tets();
  const CutResult r = cube.sweep({-0.01, -0.01}, {0.05, 0.05});
  cube.expect_invariants();
  EXPECT_EQ(r.tets_split, 0);
  EXPECT_EQ(cube.mesh.num_tets(), tets0);
  EXPECT_NEAR(open_cut_area(cube.mesh), 2 * std::sqrt(2.0) * kSide * kSide, 1e-9);
  EXPECT_EQ(mesh_pieces(cube.mesh).size(), 2u);
}

TEST(CutCases, ThroughNodesAndAlongEdgesCrossingCells) {
  // x + y = 4 cm holds node columns and vertical edges but cuts across the Kuhn tets.
  Cube cube;
  const CutResult r = cube.sweep({0.05, -0.01}, {-0.01, 0.05});
  cube.expect_invariants();
  EXPECT_GT(r.tets_split, 0);
  EXPECT_NEAR(open_cut_area(cube.mesh), 2 * std::sqrt(2.0) * kSide * kSide, 1e-9);
  EXPECT_EQ(mesh_pieces(cube.mesh).size(), 2u);
}

TEST(CutCases, NearANodePlaneSnapsInsteadOfMakingSlivers) {
  // 0.1 mm off the node plane x = 2 cm, far inside the snap distance (0.1 x 1.7 cm).
  Cube cube;
  const CutResult r = cube.sweep({0.0201, -0.01}, {0.0201, 0.05});
  cube.expect_invariants();
  EXPECT_EQ(r.tets_split, 0);
  // Interior nodes of the plane are moved the 0.1 mm onto the blade (CutOptions::relocate),
  // boundary nodes stay: the walls tilt by at most 0.1 mm over a cell, area within 1e-4.
  EXPECT_FALSE(r.moved_nodes.empty());
  EXPECT_NEAR(open_cut_area(cube.mesh), 2 * kSide * kSide, 1e-4 * 2 * kSide * kSide);
}

TEST(CutCases, RecuttingTheSamePlaceAndBesideIt) {
  Cube cube;
  cube.sweep({0.025, -0.01}, {0.025, 0.05});
  const int tets = cube.mesh.num_tets(), nodes = cube.mesh.num_nodes();
  const CutResult again = cube.sweep({0.025, -0.01}, {0.025, 0.05});
  cube.expect_invariants();
  EXPECT_EQ(again.tets_split, 0);
  EXPECT_EQ(again.nodes_added, 0);
  EXPECT_EQ(cube.mesh.num_tets(), tets);
  EXPECT_EQ(cube.mesh.num_nodes(), nodes);
  EXPECT_NEAR(open_cut_area(cube.mesh), 2 * kSide * kSide, 1e-9);
  // 1 mm beside it: inside the snap distance of the new nodes, so it reuses the first cut.
  cube.sweep({0.026, -0.01}, {0.026, 0.05});
  cube.expect_invariants();
  // A real second cut 3 mm away severs a slab.
  cube.sweep({0.028, -0.01}, {0.028, 0.05});
  cube.expect_invariants();
  EXPECT_GE(mesh_pieces(cube.mesh).size(), 2u);
  EXPECT_NEAR(total_volume(cube.mesh), cube.v0, 1e-12 * cube.v0);
}

TEST(CutCases, SeveredPieceIsFoundAsFree) {
  Cube cube;
  std::vector<std::uint8_t> anchored(cube.mesh.nodes.size(), 0);
  for (int v = 0; v < cube.mesh.num_nodes(); ++v) anchored[v] = cube.mesh.nodes[v].x() == 0.0;
  EXPECT_TRUE(free_pieces(cube.mesh, anchored).empty());
  cube.sweep({0.025, -0.01}, {0.025, 0.05});
  anchored.resize(cube.mesh.nodes.size(), 0);  // new nodes are not anchored
  const auto free = free_pieces(cube.mesh, anchored);
  ASSERT_EQ(free.size(), 1u);
  double volume = 0;
  for (int t : free[0].tets) volume += tet_volume(cube.mesh, t);
  EXPECT_NEAR(volume, 0.015 * kSide * kSide, 1e-12);
  for (int v : free[0].nodes) EXPECT_GE(cube.mesh.nodes[v].x(), 0.025 - 1e-12);
}

// The fallback behind the anchor rule (simulation.cpp, hold_what_the_factor_finds_singular):
// when a severed piece is NOT held, the factor of the stiffness on the free DOFs fails at a
// DOF of that piece, and the smallest face-connected piece through its node is the piece the
// anchor rule would have held. Held, the same system factors.
TEST(CutCases, TheFactorPointsAtAPieceNothingHolds) {
  Cube cube;
  cube.sweep({0.025, -0.01}, {0.025, 0.05});
  const TetMesh& mesh = cube.mesh;
  std::vector<std::uint8_t> anchored(mesh.nodes.size(), 0);
  for (int v = 0; v < mesh.num_nodes(); ++v) anchored[v] = mesh.nodes[v].x() == 0.0;
  const auto free = free_pieces(mesh, anchored);
  ASSERT_EQ(free.size(), 1u);
  // Free DOFs: every DOF of a node that is not fixed (x = 0).
  DofMap dofs;
  dofs.row_of.assign(3 * mesh.nodes.size(), -1);
  for (int v = 0; v < mesh.num_nodes(); ++v)
    if (!anchored[v])
      for (int c = 0; c < 3; ++c) {
        dofs.row_of[3 * v + c] = dofs.rows();
        dofs.global_of.push_back(3 * v + c);
      }
  std::vector<int> all(mesh.tets.size());
  std::iota(all.begin(), all.end(), 0);
  const SparseMatrix k =
      assemble_stiffness(mesh, ElementStiffnessCache(mesh, Material{}), all, dofs);
  const int column = SparseCholesky::first_failing_column(k);
  ASSERT_GE(column, 0);
  EXPECT_TRUE(std::binary_search(free[0].nodes.begin(), free[0].nodes.end(),
                                 dofs.global_of[static_cast<size_t>(column)] / 3))
      << "the factor failed at a node outside the severed piece";
  auto solver = make_cpu_solver(CgPreconditioner::kCholesky);
  solver->set_matrix(k);
  const int dof = solver->singular_dof();
  ASSERT_GE(dof, 0) << "a severed piece nothing holds must not factor";
  const int node = dofs.global_of[static_cast<size_t>(dof)] / 3;
  const std::vector<MeshPiece> pieces = face_connected_pieces(mesh);
  const MeshPiece* piece = smallest_piece_with_node(pieces, node);
  ASSERT_NE(piece, nullptr);
  EXPECT_EQ(piece->tets, free[0].tets) << "node " << node << " at " << mesh.nodes[node].transpose();
  // The piece held (its DOFs left out of the factor): it factors, and says so.
  std::vector<std::uint8_t> held(static_cast<size_t>(k.rows()), 0);
  for (int v : free[0].nodes)
    for (int c = 0; c < 3; ++c) held[static_cast<size_t>(dofs.row_of[3 * v + c])] = 1;
  solver->set_matrix(k, held);
  EXPECT_EQ(solver->singular_dof(), -1);
  EXPECT_EQ(solver->preconditioner(), "cholesky");
}

TEST(CutCases, LockedNodeIsNeverDuplicatedAndTheBladeStops) {
  TetMesh probe = cube_mesh();
  std::vector<std::uint8_t> locked(probe.nodes.size(), 0);
  int centre = -1;
  for (int v = 0; v < probe.num_nodes(); ++v)
    if ((probe.nodes[v] - Vec3(0.02, 0.02, 0.02)).norm() < 1e-12) centre = v;
  ASSERT_GE(centre, 0);
  locked[centre] = 1;
  Cube cube(locked);
  const CutResult r = cube.sweep({0.02, -0.01}, {0.02, 0.05});
  cube.expect_invariants();
  EXPECT_TRUE(r.reached_interface);
  for (const NewNode& n : r.new_nodes) EXPECT_NE(n.a, centre);
  // The tissue stays connected through the faces around the locked node.
  EXPECT_EQ(mesh_pieces(cube.mesh).size(), 1u);
  EXPECT_GT(open_cut_area(cube.mesh), 0.0);
}

TEST(CutCases, NonCuttableTetsAreNeverSplitOrSeparated) {
  TetMesh probe = cube_mesh();
  std::vector<std::uint8_t> cuttable(probe.tets.size(), 0);
  for (int t = 0; t < probe.num_tets(); ++t) {
    Vec3 c = Vec3::Zero();
    for (int v : probe.tets[t]) c += probe.nodes[v] / 4;
    cuttable[t] = c.z() < 0.02;  // the bottom half is the operation part
  }
  Cube cube({}, cuttable);
  const std::vector<Tet> before(cube.mesh.tets.begin(), cube.mesh.tets.end());
  const CutResult r = cube.sweep({0.025, -0.01}, {0.025, 0.05});
  cube.expect_invariants();
  for (int t = 0; t < static_cast<int>(before.size()); ++t)
    if (!cuttable[t]) {
      EXPECT_EQ(cube.mesh.tets[t], before[t]);
    }
  for (const NewNode& n : r.new_nodes)
    if (n.kind == NewNode::Kind::kDuplicate) {
      EXPECT_FALSE(cube.state.locked[n.a]);
    }
  EXPECT_EQ(mesh_pieces(cube.mesh).size(), 1u);
  // The bottom half opens up to the last layer of cells, whose crossing edges at z = 2 cm
  // join two locked nodes and stay whole: measured 1.5 cm of the 2 cm.
  EXPECT_NEAR(open_cut_area(cube.mesh), 2 * 0.015 * kSide, 1e-9);
}

TEST(CutCases, PlungeAlongTheEdgeCutsNothing) {
  Cube cube;
  BladeEdge a = edge_at(0.025, 0.02), b = a;
  b.tip.z() -= 0.005;
  b.heel.z() -= 0.005;
  const CutResult r = cut_sweep(cube.mesh, cube.state, a, b);
  EXPECT_EQ(r.tets_split + r.nodes_added + r.cut_faces_added, 0);
}

}  // namespace
}  // namespace stc
