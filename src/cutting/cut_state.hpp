// What the cutter keeps beside the TetMesh between cuts, index-aligned with it. Every cutting
// function takes (TetMesh&, CutState&) and grows both together.
#pragma once

#include "cutting/tet_grid.hpp"
#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace stc {

struct CutState {
  // Per node: never duplicated by a cut (the interface to the condensed part). Nodes of
  // non-cuttable tets are always locked (make_cut_state enforces it), so "an edge with both
  // ends locked is never split" also keeps every edge of a non-cuttable tet whole.
  std::vector<std::uint8_t> locked;
  // Per tet: part of the operation part; only these are split, cut or separated.
  std::vector<std::uint8_t> cuttable;
  // Per tet: the volume of the original input tet it descends from (its "size class", docs/SCENE.md
  // "Cut invariants").
  std::vector<double> origin_volume;
  // Per node: the tets that use it (kept up to date by every edit).
  std::vector<std::vector<int>> node_tets;
  // Cuttable tets by rest-position box.
  TetGrid grid;
  // The current stroke's sweep triangles (every sweep since the blade began this continuous
  // cut, capped) and the last sweep's end edge (tip, heel). A sweep that starts where the last
  // one ended also marks faces whose centroid lies in the stroke's earlier triangles: faces
  // that only appear when this sweep splits the tets around them, and that this sweep's own
  // triangles would not claim.
  std::vector<std::array<Vec3, 3>> last_sweep;
  std::vector<int> last_sweep_bands;  // how many of last_sweep each band gave, oldest first
  // The same stroke's bands as the blade's edge swept them: no margin beyond the tip and the
  // heel or ahead of the motion (closed_marks.hpp opens only what lies along it), same cap.
  std::vector<std::array<Vec3, 3>> blade_sweep;
  // Per node (grown on demand): on the current stroke's cut surface - created on it by a
  // split, taken onto it by the snap rule, or a copy made by opening it. A triangle of the
  // stroke treats these as "on" where they lie within its snap distance of its plane, and any
  // of them may be a corner of a face it marks, so a face whose nodes came onto the cut in
  // different sweeps (a slow blade, a curved or twisting path) is still recognised as lying
  // on the cut (triangle_cut.cpp).
  std::vector<std::uint8_t> on_stroke;
  // Per node (grown on demand): moved onto a border of a cut once (split_along_border); it
  // is never moved there again.
  std::vector<std::uint8_t> moved_to_border;
  // Per node (grown on demand): put inside a closed mark at a stroke's end (closed_marks.hpp).
  // A mark with such a corner that separation still holds shut is not split again: each later
  // stroke touching it would add another node.
  std::vector<std::uint8_t> opened_at_end;
  // Per node (grown on demand): taken onto the current stroke's surface extended past one of
  // its borders (a tet the border runs through is cut by a triangle's whole plane, and a
  // crossing beyond the triangle moved this node onto that plane). Not on the cut - no face with
  // such a corner opens - but an edge from it to a node on the cut lies along the surface, and
  // where that edge crosses a border it is split there (split_along_border), also when a later
  // triangle of a curved stroke, not coplanar with the one that took it, conforms that border.
  std::vector<std::uint8_t> on_extension;
  // Where the last band's tip and heel paths ended (cut_band conforms them from there).
  std::array<Vec3, 2> border_from = {Vec3::Constant(NAN), Vec3::Constant(NAN)};
  std::array<Vec3, 2> last_sweep_end = {Vec3::Constant(NAN), Vec3::Constant(NAN)};
  // The last band's triangles (as inserted, margins included) and its front, the border the
  // next band carries the cut on from; finish_stroke conforms the cut to it (cut_sweep.hpp).
  std::vector<std::array<Vec3, 3>> last_band;
  // The front as a polyline, tip first (its segment k lies on triangle 2k + 1 of last_band),
  // and which way each of its points moved (unit, or 0).
  std::vector<Vec3> last_front, last_front_motion;
  // The paths the stroke's tip and heel took (no margin; points kept a little apart, the
  // newest always) and the way past each point (unit: down the blade past the tip, up past the
  // heel): a marked face's corner may lie only a little past them (cut_sweep.cpp).
  std::vector<Vec3> tip_path, tip_past, heel_path, heel_past;
  // Where the stroke started (the back edge of its first band that moves across the blade's
  // edge - a blade pressed in first moves along it -, margins below the tip and above the heel
  // included) and the way back past it (unit: against that band's motion across the edge): a
  // marked face's corner, at the skin too, may lie at most its slack behind it (cut_sweep.cpp).
  std::vector<Vec3> start_line, start_past;
  // The start line is still to be found (the stroke has not yet moved across the blade's edge);
  // never for a stroke that begins inside the last one's incision.
  bool start_pending = false;
  double stroke_margin = 0;  // the last band's margin (CutOptions::front_margin)
  // Faces the stroke's cuts refused only because a corner lay past the blade, tested again
  // by its later cuts (mark_deferred_faces, triangle_cut.hpp).
  std::vector<std::array<int, 3>> deferred_faces;
  // The tets the current stroke changed (may repeat): smoothed when the next one begins
  // (cut_smoothing.hpp).
  std::vector<int> stroke_tets;
  // At least the length of every edge (rest): the input's longest, raised when a node moves
  // (relocate_node); a split or a copy makes no longer edge. 0: unknown.
  double longest_edge_bound = 0;
};

// locked: per node (empty = none); cuttable: per tet (empty = all). Also sizes
// mesh.cut_faces to one entry per tet.
CutState make_cut_state(TetMesh& mesh, std::vector<std::uint8_t> locked,
                        std::vector<std::uint8_t> cuttable);

inline bool is_on_stroke(const CutState& state, int v) {
  return static_cast<size_t>(v) < state.on_stroke.size() && state.on_stroke[v];
}
inline void set_on_stroke(CutState& state, int v) {
  if (state.on_stroke.size() <= static_cast<size_t>(v)) state.on_stroke.resize(v + 1, 0);
  state.on_stroke[v] = 1;
}

inline bool is_on_extension(const CutState& state, int v) {
  return static_cast<size_t>(v) < state.on_extension.size() && state.on_extension[v];
}
inline void set_on_extension(CutState& state, int v) {
  if (state.on_extension.size() <= static_cast<size_t>(v)) state.on_extension.resize(v + 1, 0);
  state.on_extension[v] = 1;
}
inline bool was_opened_at_end(const CutState& state, int v) {
  return static_cast<size_t>(v) < state.opened_at_end.size() && state.opened_at_end[v];
}
inline void set_opened_at_end(CutState& state, int v) {
  if (state.opened_at_end.size() <= static_cast<size_t>(v)) state.opened_at_end.resize(v + 1, 0);
  state.opened_at_end[v] = 1;
}
inline bool was_moved_to_border(const CutState& state, int v) {
  return static_cast<size_t>(v) < state.moved_to_border.size() && state.moved_to_border[v];
}
inline void set_moved_to_border(CutState& state, int v) {
  if (state.moved_to_border.size() <= static_cast<size_t>(v))
    state.moved_to_border.resize(v + 1, 0);
  state.moved_to_border[v] = 1;
}

// The tets that use both a and b, ascending.
std::vector<int> tets_with_edge(const CutState& state, int a, int b);

// v's star (state.node_tets[v]) with its faces through v matched: entry [k][f] is the position
// in the star of the tet across local face f of star tet k, or -1 where that face is on the
// boundary or does not touch v (f opposite v). A tet across a face through v uses v, so it is in
// the star: one sort of the star's faces answers what a neighbour_across per face (a scan of a
// corner's tets) would.
std::vector<std::array<int, 4>> star_neighbours(const TetMesh& mesh, const CutState& state, int v);

}  // namespace stc
