// Moving a node's rest position inside its own star: onto a cut instead of splitting a sliver
// off (triangle_cut.cpp, "relocate") and to raise the smallest dihedral angle around a cut
// (cut_smoothing.hpp). docs/DESIGN.md section 8 says why the volume stays exact.
#pragma once

#include "cutting/cut_state.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"

namespace stc {

// Angles (degrees) this close are equal for the quality guards of node moves: a move along an
// edge of the star often leaves its smallest angle the same in exact arithmetic, and a decision
// must not rest on the last digits of a position (the gl and cpu backends map the blade into
// rest coordinates ~1e-12 apart).
constexpr double kAngleRoundOffDeg = 1e-6;

// How node v may move without moving any surface (docs/DESIGN.md section 8, "Smooth"):
//  - kInsideStar: unlocked, every tet of its star cuttable, no face touching v on the boundary or
//    on a cut. The star's outer faces are interior and fixed, so wherever v goes while every star
//    tet stays positive, the star tiles the same cavity: the volume is exact.
//  - kInPlane: unlocked, star cuttable, and the faces touching v that lie on the boundary (an
//    opened cut's walls, the tissue's surface) form one fan, flat to round-off (every corner
//    within 1e-9 of the star's scale of one plane, all facing one way), while no face touching v
//    is a cut that has not opened. A move within that plane keeps the surface where it is (the
//    fan still tiles the same flat polygon) and the volume exact; `normal` is set to the fan's
//    unit normal (`axis`).
//  - kOnLine: as kInPlane, but the boundary faces touching v form two flat fans in two planes
//    at an angle (the crease where an opened cut's wall meets another wall or a flat stretch of
//    the tissue's surface). A move along the planes' common line keeps each fan in its plane
//    and the volume exact; `axis` is set to the line's unit direction. Most nodes of the thin
//    tets a cut leaves lie on such creases (random sweeps on the thigh, box and a liver: 59 %
//    of their corners that could not move otherwise).
//  - kNone: none of these.
enum class NodeMove { kNone, kInsideStar, kInPlane, kOnLine };
NodeMove how_node_may_move(const TetMesh& mesh, const CutState& state, int v, Vec3& axis);

// how_node_may_move(...) == kInsideStar (a relocation onto the cut moves only such nodes).
bool may_move_inside_star(const TetMesh& mesh, const CutState& state, int v);

// The smallest dihedral angle (degrees) of v's star with v at x, or -1 when a tet of it would
// keep no more than `guard` x its size class (or turn over).
double star_smallest_dihedral(const TetMesh& mesh, const CutState& state, int v, const Vec3& x,
                              double guard);

// The longest edge from v in its star.
double star_longest_edge(const TetMesh& mesh, const CutState& state, int v);

// Moves v to x and records it: its star's tets changed (grid boxes refreshed), v moved, the
// state's edge bound raised.
void move_node(TetMesh& mesh, CutState& state, int v, const Vec3& x, CutResult& result);

}  // namespace stc
