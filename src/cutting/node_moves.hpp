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

// How node v may move without moving any surface or cut (docs/DESIGN.md section 8, "Smooth").
// The faces that must stay where they are: those touching v on the boundary (an opened cut's
// walls, the tissue's surface; they form one fan, a single cycle around v) and the cuts that
// have not opened (marked faces whose tets are still joined).
//  - kInsideStar: unlocked, every tet of its star cuttable, no such face. The star's outer
//    faces are interior and fixed, so wherever v goes while every star tet stays positive, the
//    star tiles the same cavity: the volume is exact.
//  - kInPlane: unlocked, star cuttable, and those faces lie in one plane through v to
//    round-off (every corner within 1e-9 of the star's scale), the boundary ones all facing
//    one way. A move within that plane keeps them where they are (they still tile the same
//    flat polygon) and the volume exact; `axis` is set to the plane's unit normal.
//  - kOnLine: as kInPlane, but in two planes at an angle (the crease where an opened cut's wall
//    meets another wall, a cut that has not opened, or a flat stretch of the tissue's surface).
//    A move along the planes' common line keeps each face in its plane and the volume exact;
//    `axis` is set to the line's unit direction.
//  - kNone: none of these.
// The corners of the thin tets a cut leaves that could move neither inside their star nor in
// a flat fan (random sweeps on the thigh, box and a liver) lay on such creases (59 %) or on cuts
// that had not opened (29 %); the rest are locked (10 %) or on curved skin.
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
