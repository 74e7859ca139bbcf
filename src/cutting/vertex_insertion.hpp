// Vertex insertion (docs/DESIGN.md section 8, "Insert"; stop 42): where neither smoothing nor a
// flip raises a thin tet, a new node inside a small cavity around it - the tet and its
// neighbours across faces on no cut, or the ring of tets around one of its edges - joined to
// every face of the cavity's boundary. The cavity's boundary faces (skin, cut walls, the faces
// it shares with the rest of the mesh) stay exactly as they were, so nothing that opened closes
// and the volume is exact; its corners all stay in the mesh. The new node is interior: the
// corners of a sliver that may not move (on the curved skin, on several cut planes) no longer
// need to.
#pragma once

#include "cutting/cut_state.hpp"

#include <array>
#include <utility>
#include <vector>

namespace stc {

// Stands for the inserted node in VertexInsertion::tets until it is appended.
inline constexpr int kInsertedNode = -1;

struct VertexInsertion {
  std::vector<int> cavity;  // ascending
  std::vector<Tet> tets;    // one per boundary face of the cavity, with kInsertedNode
  Vec3 point = Vec3::Zero();
  Tet host{};  // the cavity tet that holds `point` (its displacement is interpolated there,
               // docs/DESIGN.md eq. (21a))
  std::array<double, 4> weights{};  // point's barycentric coordinates in `host`
  double size_class = 0;            // the smallest of the cavity's: the new tets'
  double before = 0;                // smallest dihedral angle of the cavity's tets
  double after = 0;                 // of the new ones
  int worst = -1;  // vertex_insertion_at: the new tet worst at the best place (a refusal's why)
};

// The insertion into `cavity` (tet indices) at the position that maximises the new tets'
// smallest dihedral angle, if one exists: every cavity tet cuttable, no face inside the cavity
// on a cut, every corner on its boundary, and every new tet above `guard` of the size class,
// tiling the cavity (volumes summing to its own to 1e-12) and no flatter by the volume ratio
// than the cavity's flattest tet.
bool vertex_insertion(const TetMesh& mesh, const CutState& state, std::vector<int> cavity,
                      double guard, VertexInsertion& insertion);

// The insertion into `cavity` at the best of given points (a cut's node near where the blade's
// tip stopped, tip_corner.hpp): the same rules on the cavity, every new tet above `guard` of the
// size class and its smallest dihedral angle at least min_angle_deg, tiling the cavity.
bool vertex_insertion_at(const TetMesh& mesh, const CutState& state, std::vector<int> cavity,
                         const std::vector<Vec3>& points, double guard, double min_angle_deg,
                         VertexInsertion& insertion);

// vertex_insertion_at into `cavity`, grown while refused across the boundary face of the worst
// new tet (a thin tet between the node and a face of the cavity nearly through it) by the tet
// beyond it - at most max_growth tets, none across a cut face and none on an edge of `keep`
// (edges that must stay on the cavity's boundary, the faces from the node to them wanted: a tet
// beyond may hold a face along them on the same plane, as a neighbouring mark's).
bool vertex_insertion_growing(const TetMesh& mesh, const CutState& state, std::vector<int> cavity,
                              const std::vector<Vec3>& points, double guard, double min_angle_deg,
                              const std::vector<std::pair<int, int>>& keep, int max_growth,
                              VertexInsertion& insertion);

// The cavity retriangulated as the star of one of its corners, `apex` (a node of the cut near
// where the blade's tip stopped, tip_corner.hpp, where a new node there makes tets too thin):
// every boundary face not on the apex joined to it, by the rules of vertex_insertion_at - every
// new tet above `guard` of the size class and its smallest dihedral angle at least
// min_angle_deg, tiling the cavity - and at least as many new tets as the cavity has (they
// take its indices, the rest appended). No node is added: insertion.tets hold the apex itself
// and insertion.point is where it lies.
bool star_from_corner(const TetMesh& mesh, const CutState& state, std::vector<int> cavity, int apex,
                      double guard, double min_angle_deg, VertexInsertion& insertion);

// Does the insertion make a face (new node, a, b) for every edge (a, b)?
bool joins_edges(const VertexInsertion& insertion, const std::vector<std::pair<int, int>>& edges);
// The same for a star from a corner: a face (apex, a, b) for every edge (a, b).
bool joins_edges_at(const VertexInsertion& insertion, int apex,
                    const std::vector<std::pair<int, int>>& edges);

// The cavities tried for tet t: t with its neighbours across its faces on no cut, and the ring
// of each of its edges (3 to 10 tets).
std::vector<std::vector<int>> insertion_cavities(const TetMesh& mesh, const CutState& state, int t);

}  // namespace stc
