// What one cut did to the mesh, so the simulation can update its own per-node and per-tet
// state (displacements, fixed flags, K^(1)) incrementally.
#pragma once

#include <array>
#include <vector>

namespace stc {

// A node appended by a cut. Process CutResult::new_nodes in order: a duplicate's parent may
// itself be a node added earlier in the same list.
struct NewNode {
  enum class Kind {
    kEdgeSplit,  // on edge (a, b) at parameter t: initialise u = (1 - t) u_a + t u_b
    kDuplicate,  // a copy of a (a node separated by the cut): initialise u = u_a, copy flags
    kInTet,      // inserted inside the tet `corners` at barycentric `weights`: u = sum w_k u_k
  };
  int index = -1;
  Kind kind = Kind::kEdgeSplit;
  int a = -1;
  int b = -1;  // kEdgeSplit only
  double t = 0;
  std::array<int, 4> corners{};     // kInTet only
  std::array<double, 4> weights{};  // kInTet only

  // Node `index` made on edge (a, b) at x_a + t (x_b - x_a).
  static NewNode on_edge(int index, int a, int b, double t) {
    NewNode node;
    node.index = index;
    node.kind = Kind::kEdgeSplit;
    node.a = a;
    node.b = b;
    node.t = t;
    return node;
  }
};

struct CutOptions {
  // An edge the cut plane crosses at parameter t < snap (or > 1 - snap) is not split: its
  // nearer end is snapped, i.e. counts as on the plane (it is never moved - moving nodes
  // would change volume). So every split has t in [snap, 1 - snap] and each bisection child
  // keeps at least `snap` of its parent's volume. Snapping only where a split would be too
  // lopsided keeps the cut as close to the blade as this allows: the cut surface lies at
  // most snap * (edge length) off the blade.
  double snap_tolerance = 0.1;
  // Shape, not only size: an edge the cut crosses at t < relocate (or > 1 - relocate) has its
  // nearer end MOVED onto the cut (rest position) instead of being split into a thin sliver,
  // when that end is an interior node of the operation part (not on the boundary, not on an
  // earlier cut, not locked) and no tet of its star gets worse than
  // min(relocate_min_dihedral_deg, its current smallest dihedral angle). Moving an interior
  // node keeps the total volume exactly (its star still tiles the same cavity).
  double relocate = 0.3;
  double relocate_min_dihedral_deg = 10.0;
  // Where the guards refuse a split and no move along the edge passes (eq. (20d)), the end
  // nearest the plane is moved onto it if it may (as a relocation, whatever its t) instead of
  // snapped in place up to half an edge off the blade.
  bool relocate_refused = true;
  // When a new stroke begins, the nodes of the tets the last stroke left with a smallest
  // dihedral angle below this (degrees) are moved to raise it where no surface moves: inside
  // their stars, or within a flat cut wall (cutting/cut_smoothing.hpp). 0: off.
  double smooth_below_deg = 10.0;
  // After the smoothing, the tets still below smooth_below_deg are flipped where a 2-3 flip or
  // an edge removal (4-4 to 7-10) over interior faces on no cut raises the smallest angle
  // (cutting/tet_flips.hpp): no node and no surface moves. false: smoothing only.
  bool flip_thin_tets = true;
  // Where no flip brings such a tet to smooth_below_deg, a new node inside a small cavity
  // around it (the tet and its neighbours across faces on no cut, or an edge's ring), joined
  // to the cavity's boundary faces, is a candidate too (cutting/vertex_insertion.hpp; only with
  // flip_thin_tets). Off by default: over 100 random strokes on a sagging TetGen liver it
  // leaves 28 % fewer tets under 5 deg, but the mesh grows with every stroke (300 strokes: +22 %
  // tets, 16 % fewer thin ones, 1.3x the time; 1,000: +41 % tets, 1.8x the time, no fewer thin
  // ones), so a long session pays for it (docs/DESIGN.md section 8, "Insert").
  bool insert_nodes = false;
  // At a stroke's end, a closed mark held shut only because all its corners lie on the cut's
  // border gets a node on an edge another mark or an opened wall shares (or at its centre),
  // and opens (cutting/closed_marks.hpp, docs/DESIGN.md section 8 "Closed marks"). Over the 40
  // strokes of the fidelity matrix 213 -> 121 closed cut faces, every stroke opens >= 95.5 %
  // (93.2 % without), the summed excess over the Hausdorff tolerance 6.29 -> 5.38; over 100
  // random strokes on a sagging TetGen liver 13 % more tets under 5 deg. The stroke's end then
  // splits tets (StepStats::stroke_finished).
  bool open_closed_marks = true;
  // No split may leave a tet below this fraction of its size class (the volume of the input
  // tet it descends from). A split that would is refused by snapping its nearer end instead;
  // docs/SCENE.md "Cut invariants": "small fraction" is this number. With snap 0.1 a tet can be cut
  // through twice (0.1^2 = 0.01) before the guard changes any cut.
  double min_volume_fraction = 0.01;
  // Shape at the split (degrees; 0: off): a bisection that would leave a piece with a smallest
  // dihedral angle under this - or under the split tet's own, where that is less - is refused
  // as min_volume_fraction refuses a piece too small: its crossing is moved along the edge to
  // where every piece passes (split_shift below), else the crossing edge's end nearest the cut
  // is snapped (counts as on it, never moved) or a border's crossing dropped. 5 deg since stop
  // 51: with the shifts the issue 9 stroke matrix measures at 5 deg what it measured at 1 deg
  // (149 / 148 of 200 shifted strokes within the Hausdorff tolerance), and after 100 random
  // strokes on a sagging TetGen liver the operation part keeps min(5 deg, its uncut smallest).
  // A mesh without a quality bound (TetGen -pQ) cuts with gaps at 5 deg (a 14 mm hole along a
  // 9 cm stroke; 2 mm at 1 deg): give such a scene 1 (docs/DESIGN.md section 8, "Shape guard",
  // eq. (20c)). A Simulation takes the scene's value (scalpel.shape_guard_deg, docs/SCENE.md),
  // whose default is this one.
  double split_min_dihedral_deg = 5;
  // Shape of what opens (degrees; 0: off): a face is not marked where opening it would leave
  // one of its two tets with two faces on the tissue's surface (the skin, an opened wall or a
  // marked face) meeting at under this angle - a flap of tissue no later repair can thicken,
  // since every tet around that edge shares its angle (docs/DESIGN.md section 8, "Where
  // bisection stops" (d)). That tet stays joined across the face, and the cut runs along its
  // other face, within the flap's thickness of the blade. Over 100 random strokes on a sagging
  // TetGen liver (five seeds) the edges where the tissue's surface folds under 5 deg fall from
  // 29 to 1; the issue 9 stroke matrix, at its own and four shifted positions, keeps its
  // figures (130 instead of 131 of 200 strokes within the Hausdorff tolerance; stop 50).
  double wedge_min_deg = 5;
  // Where the guards (min_volume_fraction, split_min_dihedral_deg) refuse a split, how far
  // along its edge (a fraction of the edge; 0: not at all) the crossing may be moved to where
  // they allow it instead of snapping an end onto the cut (a triangle's split) or dropping the
  // crossing (a border's; its edge lies on the cut, so only the border moves). The cut then
  // stays within a fraction of an edge of the blade where the guard held it up to half an edge
  // off: with the 5 deg guard, 103 -> 149 of issue 9's 200 shifted matrix strokes within the
  // Hausdorff tolerance (docs/DESIGN.md section 8 "Shape guard", eq. (20d); stop 51).
  double split_shift = 0.25;
  double border_shift = 0.25;
  // Barycentric slack of "inside the sweep triangle" (crossing points and face centroids),
  // so a cut along a triangle's border and consecutive sweeps leave no gap.
  double inside_tolerance = 1e-9;
  // The swept band is extended by this much beyond the blade's tip and heel and ahead of its
  // motion (m; negative = front_margin_fraction of the mean edge length of the tets the band
  // meets). A crack front inside a tet cannot open (its nodes' stars stay connected). The
  // tip's and heel's paths are conformed at every step (the tets they run through are split
  // along them), the blade's leading edge when the stroke ends (finish_stroke); between steps
  // the margin ahead lets the opening follow the blade to within about an element.
  double front_margin = -1;
  double front_margin_fraction = 0.25;
  // How far ahead of the blade's edge (along its motion) a face the band opens may reach while
  // the stroke goes on: each corner at most front_corner_reach x the front margin plus
  // front_corner_slack x its slack (kOnCutSlack x the face's longest edge, cutting/
  // triangle_cut.hpp) ahead of the edge; at the stroke's end (finish_stroke) at most its slack
  // ahead of where the blade stopped. The tissue ahead is still split by the whole margin. A
  // face opened farther ahead stays open if the blade stops there: the fine liver2's straight
  // strokes opened a face with a corner 1.19 mm past the blade's last position (1.32 x the
  // Hausdorff tolerance) when the limit was only the distance to the band cut short at 3/4 of
  // the margin (docs/DESIGN.md section 8, "Mark"). Negative: no limit.
  double front_corner_reach = 0.25;
  double front_corner_slack = 0.25;
  // The same below the path the blade's tip took and above its heel's, along the blade: each
  // corner at most path_corner_reach x the front margin plus path_corner_slack x its slack past
  // them. The band reaches a margin past both, and a corner could lie its slack past that: the
  // 50k liver's tilted strokes opened faces with a corner 2.15 mm below the tip (1.5 x the
  // Hausdorff tolerance). A face refused by this limit or the one ahead is tested again as the
  // blade moves on (docs/DESIGN.md section 8, "Mark"). Negative: no limit.
  double path_corner_reach = 1.0;
  double path_corner_slack = 0.25;
  // And behind where the stroke started inside the tissue (against its first motion across the
  // blade's edge, where there is tissue behind the edge): each corner at most its slack, a
  // corner on the tissue's boundary too (whose slack from the stroke's surface is
  // kSkinCornerSlack times larger in every other direction: the skin is where the blade's edge
  // is extrapolated across it, which moves the surface off its plane, not back past its start).
  // Without it a curved tilted stroke on the 50k liver opened a face with a skin corner 3.2 mm
  // behind its start (2.27 x the Hausdorff tolerance; docs/DESIGN.md section 8, "Mark"). Not
  // where the blade came in from outside (the skin behind its first band is tissue it passed),
  // nor where a stroke begins inside the last one's incision.
  bool start_corner_limit = true;
  // Where the band is conformed along the tip's path (eq. (19a)), an edge with an end this
  // fraction of the snap distance (snap_tolerance x its star's longest edge) off the band's
  // plane counts as on the cut, as one from a node on it: on a curved stroke such a node lies
  // between the bands' planes, is "on" none of them, and the edges from it were left whole - a
  // hole above the tip's path (2.8 mm, 1.7 x the Hausdorff tolerance, on the 36k liver's curved
  // tilted slow stroke). Not along the heel's path (no stroke of the fidelity matrix gains; the
  // coarse liver's belly cut opens 152 % of its sweep). docs/DESIGN.md section 8 "Borders". 0: off.
  double path_border_snap = 0.75;
  // Where the band is conformed along the tip's path (eq. (19a)), an edge crosses the border
  // where its ends lie on either side of the path the tip took (CutState::tip_path: the blade's
  // tip without the band's margin; "past" it is down the blade), not of the line through the
  // band's border segment. That segment runs from the last band's margin-extended tip to this
  // one's: the border lay a front margin (a quarter of the mean edge) below the tip, so the faces
  // reached that far past it (the thigh's straight vertical stroke: 2.56 mm, 0.90 x the Hausdorff
  // tolerance, everywhere along its tip), and a slow stroke's segment is one 0.2 mm step while
  // the tip's rest position moves up to 0.3 mm up or down between steps (the stroke follows the
  // faceted skin), so the line's direction was noise. Issue 9's matrix at five positions: 163 ->
  // 169 of 200 strokes within the Hausdorff tolerance (docs/DESIGN.md section 8 "Borders").
  bool tip_border_on_path = true;
  // At a stroke's end (finish_stroke) the last band reached back a front margin along its
  // motion is cut and marked with it, so the faces the front's split makes behind a slow
  // stroke's one-step band open (over issue 9's 200 shifted matrix strokes the summed excess over
  // the Hausdorff tolerance 16.1 -> 14.6, none worse; the thigh's straight vertical 3 mm stroke
  // at one shifted position 3.66 -> 2.17 x; docs/DESIGN.md section 8, "A stroke's end", eq.
  // (19c)).
  bool end_band_reaches_back = true;
  // At a stroke's end, where no marked face comes within a front margin of the tip's last
  // position, a node is put there and the triangles from it to the edges of the opened walls
  // facing it are marked, to open with the stroke's end (cutting/tip_corner.hpp; docs/DESIGN.md
  // section 8, "The tip's corner", eq. (19d); stop 53: the thigh's curved 45-degree 3 mm stroke
  // 1.52 -> 1.12 x the Hausdorff tolerance, issue 9's 200 shifted strokes' summed excess over it
  // 14.64 -> 14.24, none worse).
  bool fill_tip_corner = true;
  // Where a new node at the tip makes tets too thin, a node of the cut within a front margin of
  // the tip fills the corner instead: the tets the triangles from it pass through are
  // retriangulated as its star (cutting/tip_corner.hpp; docs/DESIGN.md section 8, "The tip's
  // corner", eq. (19d')).
  bool tip_corner_from_node = true;
  // A closed mark at a stroke's end whose edge shared with another mark the guards keep whole is
  // split at its centre instead (cutting/closed_marks.hpp).
  bool open_marks_at_centre = true;
  // A closed mark counts as lying along the blade's sweep with its corners within the slack of
  // the larger of its longest edge and the edge of the input tet it was split from (the scale
  // of issue 9's Hausdorff tolerance): a mark split small near the tip's path was judged by its
  // own size and left shut (closed_marks.hpp; docs/DESIGN.md section 8, "Closed marks"; stop 53).
  bool open_marks_at_input_scale = true;
  // Where the guards refuse an opening split at an edge's midpoint, the nearest place along
  // the edge they allow (0.4-0.6, 0.3-0.7, 0.2-0.8): the node's fan is the marks' two parts
  // wherever it lies (closed_marks.hpp; stop 53). Issue 9's 200 shifted strokes with both:
  // 149 -> 159 within the Hausdorff tolerance, summed excess 14.24 -> 9.87.
  bool opening_split_shift = true;
  // How many times the stroke's end splits again what opened walls still hold shut (closed_marks
  // .hpp; each round only while the last opened more).
  int opening_rounds = 2;
};

struct CutResult {
  // Tets whose node list changed or that were appended, ascending, unique. Split tets keep
  // their index for the first child; the other children are appended.
  std::vector<int> changed_tets;
  std::vector<NewNode> new_nodes;
  // Existing nodes whose rest position a cut moved onto the cut surface (their tets are in
  // changed_tets: their element matrices change).
  std::vector<int> moved_nodes;
  int tets_split = 0;              // parent tets bisected (a tet split twice counts twice)
  int nodes_added = 0;             // edge nodes + duplicates
  int cut_faces_added = 0;         // net new cut faces (each face once; a halved one counts 1 more)
  bool reached_interface = false;  // cut faces dropped so a locked node stays whole
  // Of moved_nodes, how many the last stroke's smoothing moved (a new stroke's first cut does
  // it first; cutting/cut_smoothing.hpp): a change of shape, not a cut.
  int nodes_smoothed = 0;
  // Flips the last stroke's tets took at the same time (cutting/tet_flips.hpp): connectivity,
  // not a cut.
  int flips = 0;
  // Of new_nodes, how many the flips inserted inside a cavity (cutting/tet_flips.hpp): shape,
  // not a cut.
  int nodes_inserted = 0;
  // Did the cut split, add or mark anything? (Moving nodes alone - the smoothing, or a node
  // relocated onto a cut that opened nothing there - changes the mesh's shape, not its cut:
  // the same stroke again relocates what the last one's smoothing moved off it.)
  bool cut_anything() const {
    return tets_split > 0 || static_cast<int>(new_nodes.size()) > nodes_inserted ||
           cut_faces_added != 0;
  }
};

}  // namespace stc
