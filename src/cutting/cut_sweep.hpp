// One cutting step: the surface the blade edge sweeps between two poses, inserted into the
// operation part of the mesh in place (docs/DESIGN.md section 8), keeping docs/SCENE.md "Cut
// invariants".
//
// The sweep between edges (A0, B0) and (A1, B1) (A = tip, B = heel) is a bilinear patch,
// approximated by the planar triangles (A0, B0, B1) and (A0, B1, A1). Each triangle is
// inserted (split + mark, triangle_cut.hpp), then the marked faces are opened
// (separation.hpp). Coordinates are REST coordinates: the mesh's nodes are rest positions.
#pragma once

#include "cutting/cut_state.hpp"
#include "cutting/triangle_cut.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/cutting/cut_result.hpp"

#include <vector>

namespace stc {

CutResult cut_sweep(TetMesh& mesh, CutState& state, const BladeEdge& from, const BladeEdge& to,
                    const CutOptions& options = {});

// The band swept between two polylines along the blade edge (tip first, same number of
// points, >= 2), e.g. the edge at two poses carried to rest coordinates through the tissue's
// deformation (rest_mapping.hpp); a straight edge is the two-point case.
CutResult cut_band(TetMesh& mesh, CutState& state, const std::vector<Vec3>& from,
                   const std::vector<Vec3>& to, const CutOptions& options = {});

// The stroke's bands (`stroke`, `bands` of its triangles each, oldest first: CutState's
// last_sweep and last_sweep_bands) as the mark phase tests them: walking back from the newest,
// a band is kept when the corners of its first triangle lie `spacing` or more from those of
// the last band kept; the newest and the oldest always (docs/DESIGN.md section 8, "Spaced
// bands"). All of `stroke` when the counts do not add up to it.
std::vector<std::array<Vec3, 3>> spaced_bands(const std::vector<std::array<Vec3, 3>>& stroke,
                                              const std::vector<int>& bands, double spacing);

// A segment of the cut surface's border (the tip's path, the heel's, where a stroke starts),
// lying on triangle `triangle` of a cut_triangles call.
struct CutBorder {
  int triangle = 0;
  Vec3 p0, p1;
  bool tip_path = false;  // a piece of the path the blade's tip took (CutOptions::path_border_snap)
};

// The end of a stroke (the blade stops, leaves the tissue, or stops cutting): the cut is
// conformed to the last band's front as it is to the tip's and heel's paths at every step, so
// it opens up to where the blade stopped, not an element short of it. Nothing to do if no band
// was cut since the last call; the stroke may go on afterwards.
CutResult finish_stroke(TetMesh& mesh, CutState& state, const CutOptions& options = {});

// Where the blade stands - its edge, or the path its tip or heel took - as a limit on how far
// past it (ahead of the edge along its motion, below the tip, above the heel) a marked face's
// corner may lie: reach + slack_fraction x the corner's slack (StrokeSurface::add_limit,
// CutOptions::front_corner_reach).
struct BladeStop {
  std::vector<Vec3> line;  // tip first along an edge
  std::vector<Vec3> past;  // per point of line: unit, or 0 where nothing is past it
  double reach = 0;
  double slack_fraction = 0;
};

// Any list of planar triangles, inserted as one cut (one separation at the end).
// also_mark_in: earlier triangles of the same stroke; faces this cut creates that lie in one of
// them are marked too (the split around a new triangle can expose a face of an old one).
// borders: where the cut surface ends inside the tissue; the faces on the cut are split there
// (split_along_border) so that the cut opens up to them.
// skin_slack: as mark_faces_on_triangle's (triangle_cut.hpp).
// marked_in: the earlier triangles whose faces are marked (default also_mark_in): a slow
// stroke's bands thinned (cut_band).
// stops: where the blade stands, if a marked face's corners are limited past it.
CutResult cut_triangles(TetMesh& mesh, CutState& state,
                        const std::vector<std::array<Vec3, 3>>& triangles,
                        const CutOptions& options = {},
                        const std::vector<std::array<Vec3, 3>>& also_mark_in = {},
                        const std::vector<CutBorder>& borders = {},
                        double skin_slack = kSkinCornerSlack,
                        const std::vector<std::array<Vec3, 3>>* marked_in = nullptr,
                        const std::vector<BladeStop>& stops = {});

}  // namespace stc
