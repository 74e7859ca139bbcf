// A node's star with its faces matched (cutting/cut_state.hpp, star_neighbours) against
// neighbour_across, face by face, for every node: on a TetGen liver cut by three tilted strokes
// (opened walls, nodes copied, a crack front still closed) and uncut (the skin alone).
#include "common/cut_fidelity_scenes.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "cutting/triangle_cut.hpp"

#include <gtest/gtest.h>

namespace stc {
namespace {

// Returns how many faces through a node have no tet across them (the boundary's fans).
int expect_stars_match_neighbour_across(const TetMesh& mesh, const CutState& state) {
  int open = 0;
  for (int v = 0; v < mesh.num_nodes(); ++v) {
    const std::vector<int>& star = state.node_tets[static_cast<size_t>(v)];
    const std::vector<std::array<int, 4>> across = star_neighbours(mesh, state, v);
    EXPECT_EQ(across.size(), star.size()) << "node " << v;
    for (size_t k = 0; k < star.size() && k < across.size(); ++k)
      for (int f = 0; f < 4; ++f) {
        const int t = star[k];
        if (mesh.tets[static_cast<size_t>(t)][static_cast<size_t>(f)] == v) {
          EXPECT_EQ(across[k][static_cast<size_t>(f)], -1) << "node " << v << ", face opposite it";
          continue;
        }
        const int other = neighbour_across(mesh, state, t, f).first;
        const int j = across[k][static_cast<size_t>(f)];
        EXPECT_EQ(j < 0 ? -1 : star[static_cast<size_t>(j)], other)
            << "node " << v << ", tet " << t << ", face " << f;
        open += other < 0;
      }
  }
  return open;
}

TEST(CutState, StarNeighboursMatchNeighbourAcrossOnACutTetGenLiver) {
  TetMesh mesh = fidelity::tetgen_liver("liver2", 5000);
  CutState state = make_cut_state(mesh, {}, {});
  const int open_uncut = expect_stars_match_neighbour_across(mesh, state);
  EXPECT_GT(open_uncut, 0);  // the skin
  const Vec3 top = fidelity::top_node(mesh);
  CutOptions options;
  int opened = 0;
  for (int k = 0; k < 3; ++k) {
    const Vec3 tip = top + Vec3(-0.02 + 0.01 * k, -0.015, -0.01 + 0.008 * k);
    const Vec3 along = Vec3(1, 0.1 * k, 0.4 - 0.3 * k).normalized();
    BladeEdge from{tip, tip + 0.04 * Vec3(0.2 * k, 1, 0.3).normalized(), Vec3::UnitZ()};
    for (int step = 0; step < 8; ++step) {
      BladeEdge to = from;
      to.tip += 0.003 * along;
      to.heel += 0.003 * along;
      opened += static_cast<int>(cut_sweep(mesh, state, from, to, options).new_nodes.size());
      from = to;
    }
    if (k < 2) finish_stroke(mesh, state, options);  // the last stroke's front stays closed
  }
  ASSERT_GT(opened, 50) << "the strokes must open the liver";
  EXPECT_GT(expect_stars_match_neighbour_across(mesh, state), open_uncut);  // walls opened
}

}  // namespace
}  // namespace stc
