// Vertex insertion (cutting/vertex_insertion.hpp, docs/DESIGN.md section 8 "Insert"): on a
// TetGen liver after six strokes, flips with insertion leave fewer thin tets than flips alone,
// with the boundary, the cut faces, the volume and the cut state as they were and each new
// node interior, where its weights in its host put it; a cut face inside a cavity, or a node
// that the cavity would lose, forbids it.
#include "common/cut_fidelity_scenes.hpp"
#include "common/cut_measures.hpp"
#include "common/cut_state_checks.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/tet_flips.hpp"
#include "cutting/triangle_cut.hpp"
#include "cutting/vertex_insertion.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace stc {
namespace {

std::multiset<std::array<int, 3>> boundary_faces(const TetMesh& mesh) {
  std::multiset<std::array<int, 3>> faces;
  for (const BoundaryTriangle& t : extract_boundary_surface(mesh).triangles) {
    std::array<int, 3> k = {t.nodes[0], t.nodes[1], t.nodes[2]};
    std::sort(k.begin(), k.end());
    faces.insert(k);
  }
  return faces;
}

// A TetGen liver after six crossing strokes that smoothed and flipped but inserted nothing.
struct StrokedLiver {
  TetMesh mesh;
  CutState state;
  double volume = 0;
};

StrokedLiver stroked_liver() {
  StrokedLiver s;
  s.mesh = fidelity::tetgen_liver("liver2", 5000);
  s.state = make_cut_state(s.mesh, {}, {});
  s.volume = total_volume(s.mesh);
  CutOptions options;
  options.insert_nodes = false;
  fidelity::crossing_strokes(s.mesh, s.state, 6, options);
  return s;
}

std::vector<int> all_tets(const TetMesh& mesh) {
  std::vector<int> all(static_cast<size_t>(mesh.num_tets()));
  for (int t = 0; t < mesh.num_tets(); ++t) all[static_cast<size_t>(t)] = t;
  return all;
}

TEST(VertexInsertion, WhereFlipsStopNodesInsideRemoveMoreThinTets) {
  StrokedLiver flipped = stroked_liver();
  StrokedLiver inserted = flipped;
  const auto surface = boundary_faces(inserted.mesh);
  const int thin_before = test::thin_tets(inserted.mesh), nodes_before = inserted.mesh.num_nodes();
  CutOptions no_insertion, insertion_on;
  no_insertion.insert_nodes = false;
  insertion_on.insert_nodes = true;
  CutResult flips_only, with_insertion;
  const FlipCounts a =
      flip_thin_tets(flipped.mesh, flipped.state, no_insertion, all_tets(flipped.mesh), flips_only);
  const FlipCounts b = flip_thin_tets(inserted.mesh, inserted.state, insertion_on,
                                      all_tets(inserted.mesh), with_insertion);
  const int thin_flipped = test::thin_tets(flipped.mesh),
            thin_inserted = test::thin_tets(inserted.mesh);
  std::printf(
      "TetGen liver, 6 strokes, tets under 5 deg %d: flips only %d (%d flips), with insertion "
      "%d (%d flips, %d insertions); tets %d / %d\n",
      thin_before, thin_flipped, a.total(), thin_inserted, b.faces + b.edges, b.insertions,
      flipped.mesh.num_tets(), inserted.mesh.num_tets());
  EXPECT_EQ(a.insertions, 0);
  EXPECT_GT(b.insertions, 0);
  EXPECT_LT(thin_inserted, thin_flipped);
  // Shape, not a cut: the boundary, the cut faces and the volume as they were.
  EXPECT_EQ(with_insertion.nodes_inserted, b.insertions);
  EXPECT_FALSE(with_insertion.cut_anything());
  EXPECT_EQ(boundary_faces(inserted.mesh), surface);
  EXPECT_NEAR(total_volume(inserted.mesh), inserted.volume, 1e-12 * inserted.volume);
  InvariantLimits limits;
  limits.initial_volume = inserted.volume;
  const auto violated = check_cut_invariants(inserted.mesh, inserted.state.origin_volume, limits);
  EXPECT_TRUE(violated.empty()) << violated.front();
  // Each new node: interior (on no boundary face), where its weights in its host put it.
  ASSERT_EQ(inserted.mesh.num_nodes(), nodes_before + b.insertions);
  std::set<int> on_boundary;
  for (const auto& face : surface) on_boundary.insert(face.begin(), face.end());
  for (const NewNode& node : with_insertion.new_nodes) {
    EXPECT_EQ(node.kind, NewNode::Kind::kInTet);
    EXPECT_GE(node.index, nodes_before);
    EXPECT_EQ(on_boundary.count(node.index), 0u);
    Vec3 at = Vec3::Zero();
    double sum = 0;
    for (size_t i = 0; i < 4; ++i) {
      EXPECT_LT(node.corners[i], node.index);
      EXPECT_GE(node.weights[i], -1e-9);
      at += node.weights[i] * inserted.mesh.nodes[static_cast<size_t>(node.corners[i])];
      sum += node.weights[i];
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    EXPECT_LT((at - inserted.mesh.nodes[static_cast<size_t>(node.index)]).norm(), 1e-12);
  }
  // The cut state follows: every tet in its corners' stars, and only there.
  EXPECT_EQ(test::stars_mismatch(inserted.mesh, inserted.state), "");
}

TEST(VertexInsertion, ACutFaceInsideTheCavityForbidsIt) {
  StrokedLiver s = stroked_liver();
  // The first thin tet with a cavity that takes a node, and a face inside that cavity.
  VertexInsertion insertion;
  std::vector<int> cavity;
  for (int t = 0; t < s.mesh.num_tets() && cavity.empty(); ++t) {
    const Tet& e = s.mesh.tets[static_cast<size_t>(t)];
    if (smallest_dihedral_deg(s.mesh.nodes[e[0]], s.mesh.nodes[e[1]], s.mesh.nodes[e[2]],
                              s.mesh.nodes[e[3]]) >= 5.0)
      continue;
    for (const std::vector<int>& c : insertion_cavities(s.mesh, s.state, t))
      if (vertex_insertion(s.mesh, s.state, c, 0.02, insertion) &&
          insertion.after > insertion.before) {
        cavity = c;
        break;
      }
  }
  ASSERT_FALSE(cavity.empty());
  EXPECT_GT(insertion.tets.size(), cavity.size());
  // Mark one face between two cavity tets as cut, on both sides.
  bool marked = false;
  for (int c : cavity) {
    for (int f = 0; f < 4 && !marked; ++f) {
      const auto [other, other_face] = neighbour_across(s.mesh, s.state, c, f);
      if (other < 0 || std::find(cavity.begin(), cavity.end(), other) == cavity.end()) continue;
      s.mesh.cut_faces[static_cast<size_t>(c)] |= static_cast<std::uint8_t>(1u << f);
      s.mesh.cut_faces[static_cast<size_t>(other)] |= static_cast<std::uint8_t>(1u << other_face);
      marked = true;
    }
    if (marked) break;
  }
  ASSERT_TRUE(marked);
  EXPECT_FALSE(vertex_insertion(s.mesh, s.state, cavity, 0.02, insertion));
}

TEST(VertexInsertion, AStarWithANodeInsideIsNotACavity) {
  // The four tets around node 4 (inside the tet 0-3): joining a new node to their boundary
  // would lose node 4.
  TetMesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0.2, 0.2, 0.2)};
  mesh.tets = {Tet{4, 1, 2, 3}, Tet{0, 4, 2, 3}, Tet{0, 1, 4, 3}, Tet{0, 1, 2, 4}};
  CutState state = make_cut_state(mesh, {}, {});
  VertexInsertion insertion;
  EXPECT_FALSE(vertex_insertion(mesh, state, {0, 1, 2, 3}, 0.02, insertion));
}

// star_from_corner (tip_corner.hpp's fill from a node of the cut): a cavity retriangulated as
// the star of one of its corners. A unit cube's six Kuhn tets all hold its main diagonal, so
// the star of its corner (0, 0, 0) is valid (every far face seen at a positive volume); the
// corner (1, 0, 0) lies in the plane of a triangle it is not on (the face y = 0 is split along
// (0, 0, 0)-(1, 0, 1)), so its star would hold a flat tet.
TEST(StarFromCorner, AConvexCavityIsTheStarOfACornerThatSeesEveryFarFace) {
  GeneratorParams g;
  g.size = Vec3(0.01, 0.01, 0.01);
  g.cells = {1, 1, 1};
  TetMesh cube = make_box_mesh(g);
  CutState state = make_cut_state(cube, {}, {});
  const auto at = [&](const Vec3& x) {
    for (int v = 0; v < cube.num_nodes(); ++v)
      if ((cube.nodes[static_cast<size_t>(v)] - x).norm() < 1e-12) return v;
    return -1;
  };
  const int origin = at(Vec3::Zero()), beside = at(Vec3(0.01, 0, 0));
  ASSERT_GE(origin, 0);
  ASSERT_GE(beside, 0);
  VertexInsertion star;
  ASSERT_TRUE(star_from_corner(cube, state, all_tets(cube), origin, 0.02, 5.0, star));
  EXPECT_EQ(star.tets.size(), 6u);  // the three far faces' two triangles each
  double volume = 0;
  for (const Tet& k : star.tets) {
    EXPECT_EQ(std::count(k.begin(), k.end(), origin), 1);
    volume += signed_volume(cube.nodes[k[0]], cube.nodes[k[1]], cube.nodes[k[2]], cube.nodes[k[3]]);
  }
  EXPECT_NEAR(volume, 1e-6, 1e-18);
  EXPECT_GE(star.after, 5.0);
  EXPECT_FALSE(star_from_corner(cube, state, all_tets(cube), beside, 0.02, 0.0, star));
  // Not a corner of the cavity: a star from a node elsewhere is not one.
  TetMesh two = cube;
  two.nodes.push_back(Vec3(0.02, 0.02, 0.02));
  CutState two_state = make_cut_state(two, {}, {});
  EXPECT_FALSE(
      star_from_corner(two, two_state, all_tets(two), two.num_nodes() - 1, 0.02, 0.0, star));
}

// Applied on a stroked liver (apply_star, tet_flips.hpp): an edge's ring retriangulated as the
// star of a corner of it keeps the boundary, the cut faces, the volume and the node count, and
// the cut state follows.
TEST(StarFromCorner, AppliedItKeepsTheBoundaryTheCutAndTheVolume) {
  StrokedLiver s = stroked_liver();
  const auto surface = boundary_faces(s.mesh);
  const auto marked_sides = [](const TetMesh& mesh) {
    int sides = 0;
    for (std::uint8_t bits : mesh.cut_faces) sides += __builtin_popcount(bits);
    return sides;
  };
  const int nodes = s.mesh.num_nodes(), marked = marked_sides(s.mesh);
  VertexInsertion star;
  int apex = -1, tried = 0;
  for (int t = 0; t < s.mesh.num_tets() && apex < 0; ++t)
    for (const std::vector<int>& c : insertion_cavities(s.mesh, s.state, t)) {
      std::set<int> corners;
      for (int k : c)
        corners.insert(s.mesh.tets[static_cast<size_t>(k)].begin(),
                       s.mesh.tets[static_cast<size_t>(k)].end());
      for (int v : corners) {
        ++tried;
        if (star_from_corner(s.mesh, s.state, c, v, 0.02, 5.0, star)) {
          apex = v;
          break;
        }
      }
      if (apex >= 0) break;
    }
  ASSERT_GE(apex, 0) << tried << " stars tried";
  const size_t cavity = star.cavity.size();
  CutResult result;
  apply_star(s.mesh, s.state, star, result);
  EXPECT_EQ(s.mesh.num_nodes(), nodes);
  EXPECT_TRUE(result.new_nodes.empty());
  EXPECT_EQ(result.changed_tets.size(), star.tets.size());
  EXPECT_GE(star.tets.size(), cavity);
  EXPECT_EQ(boundary_faces(s.mesh), surface);
  EXPECT_EQ(marked_sides(s.mesh), marked);
  EXPECT_NEAR(total_volume(s.mesh), s.volume, 1e-12 * s.volume);
  for (int t : result.changed_tets) {
    const Tet& k = s.mesh.tets[static_cast<size_t>(t)];
    EXPECT_EQ(std::count(k.begin(), k.end(), apex), 1) << t;
    EXPECT_GE(smallest_dihedral_deg(s.mesh.nodes[k[0]], s.mesh.nodes[k[1]], s.mesh.nodes[k[2]],
                                    s.mesh.nodes[k[3]]),
              5.0 - 1e-9);
  }
  InvariantLimits limits;
  limits.initial_volume = s.volume;
  const auto violated = check_cut_invariants(s.mesh, s.state.origin_volume, limits);
  EXPECT_TRUE(violated.empty()) << violated.front();
  EXPECT_EQ(test::stars_mismatch(s.mesh, s.state), "");
}

}  // namespace
}  // namespace stc
