#include "cutting/cut_sweep.hpp"

#include "collision/tissue_samples.hpp"
#include "cutting/closed_marks.hpp"
#include "cutting/cut_smoothing.hpp"
#include "cutting/earlier_triangles.hpp"
#include "cutting/separation.hpp"
#include "cutting/tip_corner.hpp"
#include "cutting/triangle_cut.hpp"

#include <algorithm>
#include <array>

namespace stc {
namespace {

// The stroke's triangles kept (every non-degenerate sweep triangle since the blade began this
// continuous cut, so that faces spanning many small sweeps - a blade moving 1 mm per step
// through 6 mm tets - are still opened), bounded so a very long stroke stays cheap.
constexpr size_t kMaxStrokeTriangles = 1024;
// How far apart (in front margins) the leading edges of the bands the mark phase tests lie.
constexpr double kBandSpacing = 0.25;

using Triangles = std::vector<std::array<Vec3, 3>>;

// A band's triangles, then the stroke's earlier ones newest first: the order a face's corners
// are looked for in.
Triangles nearest_first(const Triangles& band, const Triangles& stroke) {
  Triangles out = band;
  out.insert(out.end(), stroke.rbegin(), stroke.rend());
  return out;
}

// Appends a band's non-degenerate triangles to the stroke's list (a new stroke: cleared first),
// keeping the newest kMaxStrokeTriangles.
void keep_in_stroke(Triangles& stroke, const Triangles& band, bool continues,
                    std::vector<int>* bands = nullptr) {
  if (!continues) stroke.clear();
  if (!continues && bands) bands->clear();
  const size_t before = stroke.size();
  for (const auto& tri : band)
    if ((tri[1] - tri[0]).cross(tri[2] - tri[0]).norm() > 0) stroke.push_back(tri);
  if (bands && stroke.size() > before) bands->push_back(static_cast<int>(stroke.size() - before));
  if (stroke.size() > kMaxStrokeTriangles) {
    size_t drop = stroke.size() - kMaxStrokeTriangles;
    stroke.erase(stroke.begin(), stroke.begin() + static_cast<long>(drop));
    // Whole bands first; a band partly dropped keeps the count of what is left of it.
    while (bands && drop > 0 && !bands->empty()) {
      const size_t first = static_cast<size_t>(bands->front());
      if (first <= drop) {
        drop -= first;
        bands->erase(bands->begin());
      } else {
        bands->front() -= static_cast<int>(drop);
        drop = 0;
      }
    }
  }
}

// Are a marked face's corners limited ahead of the blade (CutOptions::front_corner_reach)?
bool limits_ahead(const CutOptions& options) {
  return options.front_corner_reach >= 0 && options.front_corner_slack >= 0;
}

// Appends x to a path of the stroke (`way`: past it), or moves the path's last point there when
// that lies within `spacing` of the one before (the newest point is always kept).
void extend_path(std::vector<Vec3>& path, std::vector<Vec3>& past, const Vec3& x, const Vec3& way,
                 double spacing) {
  if (path.size() >= 2 && (path[path.size() - 2] - x).norm() < spacing) {
    path.back() = x;
    past.back() = way;
    return;
  }
  path.push_back(x);
  past.push_back(way);
  if (path.size() > kMaxStrokeTriangles) {  // as long as the stroke's kept triangles reach
    path.erase(path.begin());
    past.erase(past.begin());
  }
}

// The stroke's tip and heel paths as limits (CutOptions::path_corner_reach), if set.
// And where the stroke started (CutOptions::start_corner_limit): a corner at most its own slack
// behind it, at the skin too.
void add_path_limits(const CutState& state, const CutOptions& options, double margin,
                     std::vector<BladeStop>& stops) {
  if (options.path_corner_reach >= 0 && options.path_corner_slack >= 0)
    for (const auto* path : {&state.tip_path, &state.heel_path}) {
      BladeStop stop;
      stop.line = *path;
      stop.past = path == &state.tip_path ? state.tip_past : state.heel_past;
      stop.reach = options.path_corner_reach * margin;
      stop.slack_fraction = options.path_corner_slack;
      stops.push_back(std::move(stop));
    }
  if (options.start_corner_limit && !state.start_line.empty()) {
    BladeStop stop;
    stop.line = state.start_line;
    stop.past = state.start_past;
    stop.slack_fraction = 1;
    stops.push_back(std::move(stop));
  }
}

// A band moves across the blade's edge (CutState::start_line) where at least this share of
// every point's motion is across it (0.5: at most 60 deg off the edge's normal).
constexpr double kAcrossShare = 0.5;
// Points per segment of the stroke's start edge tested for tissue behind them.
constexpr int kStartSamples = 8;

// At most this many faces wait (CutState::deferred_faces); the oldest go first.
constexpr size_t kMaxDeferredFaces = 4096;

long count_marked_face_sides(const TetMesh& mesh) {
  // Four bits per tet, counted by a table of all 256 bytes: __builtin_popcount without a popcnt
  // target is a library call per tet, ~1 ms a cut on the 70k-tet organ (this runs twice per
  // cut), and two lookups of a 16-entry table per tet still cost ~0.1 ms each time.
  static constexpr auto kBits = [] {
    std::array<std::uint8_t, 256> bits{};
    for (int b = 1; b < 256; ++b)
      bits[static_cast<size_t>(b)] = (b & 1) + bits[static_cast<size_t>(b >> 1)];
    return bits;
  }();
  long sides = 0;
  for (std::uint8_t bits : mesh.cut_faces) sides += kBits[bits];
  return sides;
}

}  // namespace

// A slow stroke adds a band every step, each reaching a front margin ahead of the blade, so
// consecutive bands overlap almost wholly (0.05 mm steps under a 1.2 mm margin on the organ
// liver: each point of the cut lies in ~25 of them); with the spacing under a band's reach,
// the kept bands still cover the stroke.
Triangles spaced_bands(const Triangles& stroke, const std::vector<int>& bands, double spacing) {
  if (bands.empty()) return stroke;
  std::vector<std::pair<size_t, size_t>> ranges;  // [first, end) of each band, oldest first
  size_t at = 0;
  for (int count : bands) {
    ranges.emplace_back(at, at + static_cast<size_t>(count));
    at += static_cast<size_t>(count);
  }
  if (at != stroke.size()) return stroke;  // not counted band by band: all of it
  std::vector<char> keep(ranges.size(), 0);
  keep.back() = keep.front() = 1;
  const std::array<Vec3, 3>* last = &stroke[ranges.back().first];
  for (size_t k = ranges.size() - 1; k-- > 1;) {
    const std::array<Vec3, 3>& lead = stroke[ranges[k].first];
    double apart = 0;
    for (int v = 0; v < 3; ++v) apart = std::max(apart, (lead[v] - (*last)[v]).norm());
    if (apart >= spacing) {
      keep[k] = 1;
      last = &lead;
    }
  }
  Triangles out;
  for (size_t k = 0; k < ranges.size(); ++k)
    if (keep[k])
      out.insert(out.end(), stroke.begin() + static_cast<long>(ranges[k].first),
                 stroke.begin() + static_cast<long>(ranges[k].second));
  return out;
}

// A cut's bookkeeping once it has changed the mesh: result.changed_tets sorted and unique, the
// ones from `changed_from` on (those this phase added) in the stroke's tets, and the counts.
void settle(const TetMesh& mesh, CutState& state, CutResult& result, size_t changed_from,
            long marked_before) {
  const auto unique = [](std::vector<int>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  };
  std::vector<int> added(result.changed_tets.begin() + static_cast<long>(changed_from),
                         result.changed_tets.end());
  unique(added);
  state.stroke_tets.insert(state.stroke_tets.end(), added.begin(), added.end());
  unique(result.changed_tets);
  if (state.stroke_tets.size() > 2 * mesh.tets.size())
    unique(state.stroke_tets);  // a long stroke: no tet twice
  result.nodes_added = static_cast<int>(result.new_nodes.size());
  // Net new cut faces: each face is marked on both of its sides (open or closed), and a cut
  // face halved by a later split counts as one more.
  result.cut_faces_added += static_cast<int>((count_marked_face_sides(mesh) - marked_before) / 2);
}

CutResult cut_triangles(TetMesh& mesh, CutState& state,
                        const std::vector<std::array<Vec3, 3>>& triangles,
                        const CutOptions& options,
                        const std::vector<std::array<Vec3, 3>>& also_mark_in,
                        const std::vector<CutBorder>& borders, double skin_slack,
                        const std::vector<std::array<Vec3, 3>>* marked_in,
                        const std::vector<BladeStop>& stops) {
  CutResult result;
  if (also_mark_in.empty()) {
    // A new stroke: the last one's cut is complete, so its tets' shapes come first (not when it
    // ends: a stroke ends on the step after the blade left, which may hold the blade still, and
    // a held pose changes nothing - docs/DESIGN.md section 8, "Smooth"). No node is on the new
    // stroke's surface yet.
    smooth_last_stroke(mesh, state, options, result);
    result.nodes_smoothed = static_cast<int>(result.moved_nodes.size());
    state.on_stroke.clear();
    state.on_extension.clear();
    state.deferred_faces.clear();
  }
  std::set<FaceKey> new_faces;
  const long marked_before = count_marked_face_sides(mesh);
  std::vector<TriangleClassification> cut;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const auto& tri : triangles) {
    cut.emplace_back(tri[0], tri[1], tri[2], options.snap_tolerance);
    Vec3 a, b;
    cut.back().bounds(a, b);
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  }
  // All splits first, then all marks (triangle_cut.hpp says why).
  // The stroke's surface, nearest first (a face's corners are looked for in this order).
  const Triangles surface = nearest_first(triangles, also_mark_in);
  const StrokeSurface stroke(surface);
  for (auto& tri : cut) split_along_triangle(mesh, state, tri, options, result);
  for (const CutBorder& border : borders)
    if (border.triangle >= 0 && static_cast<size_t>(border.triangle) < cut.size())
      split_along_border(mesh, state, cut[static_cast<size_t>(border.triangle)], border.p0,
                         border.p1, options, stroke, result, border.tip_path);
  StrokeSurface marks(surface);
  for (const BladeStop& stop : stops)
    marks.add_limit(stop.line, stop.past, stop.reach, stop.slack_fraction);
  // The mesh no longer changes: every classification shares the nodes' scales.
  NodeScales scales;
  for (auto& tri : cut) {
    Vec3 a, b;
    tri.bounds(a, b);
    tri.share_scales(&scales);
    mark_faces_on_triangle(mesh, state, tri, a, b, options, marks, skin_slack, result, new_faces);
  }
  // Earlier triangles of the same stroke: a face that only now appears (this cut split the
  // tets around it) may lie in any of them.
  if (!triangles.empty())
    mark_faces_on_earlier_triangles(mesh, state, marked_in ? *marked_in : also_mark_in, lo, hi,
                                    options, marks, skin_slack, scales, result, new_faces);
  // Faces earlier cuts refused only for lying past the blade, tested again now that it has
  // moved on; this cut's own such faces join them (oldest first).
  std::set<FaceKey> deferred_marked;
  if (marks.limited()) {
    std::vector<FaceKey> still =
        mark_deferred_faces(mesh, state, state.deferred_faces, marks, skin_slack, deferred_marked,
                            options.wedge_min_deg);
    std::set<FaceKey> waiting(still.begin(), still.end());
    for (const FaceKey& key : marks.deferred())
      if (waiting.insert(key).second) still.push_back(key);
    if (still.size() > kMaxDeferredFaces)
      still.erase(still.begin(), still.end() - static_cast<long>(kMaxDeferredFaces));
    state.deferred_faces = std::move(still);
  }
  if (!triangles.empty()) {
    // Marked faces lie inside the triangles' box (their tets overlap it), or are deferred ones.
    std::vector<int> region;
    for (int t : state.grid.query(mesh, lo, hi))
      if (state.cuttable[t]) region.push_back(t);
    if (!deferred_marked.empty()) {
      for (const FaceKey& key : deferred_marked) {
        new_faces.insert(key);
        for (int v : key)
          for (int t : state.node_tets[static_cast<size_t>(v)])
            if (state.cuttable[t]) region.push_back(t);
      }
      std::sort(region.begin(), region.end());
      region.erase(std::unique(region.begin(), region.end()), region.end());
    }
    separate_along_cuts(mesh, state, region, result, new_faces);
  }
  settle(mesh, state, result, 0, marked_before);
  return result;
}

CutResult cut_sweep(TetMesh& mesh, CutState& state, const BladeEdge& from, const BladeEdge& to,
                    const CutOptions& options) {
  return cut_band(mesh, state, {from.tip, from.heel}, {to.tip, to.heel}, options);
}

CutResult cut_band(TetMesh& mesh, CutState& state, const std::vector<Vec3>& from,
                   const std::vector<Vec3>& to, const CutOptions& options) {
  if (from.size() < 2 || from.size() != to.size()) return {};
  const double scale =
      std::max((from.back() - from.front()).norm(), (to.front() - from.front()).norm());
  const bool continues = (from.front() - state.last_sweep_end[0]).norm() <= 1e-9 * scale &&
                         (from.back() - state.last_sweep_end[1]).norm() <= 1e-9 * scale;
  // The margin beyond the blade's fronts (CutOptions::front_margin).
  double margin = options.front_margin;
  if (margin < 0) {
    Vec3 lo = from[0], hi = from[0];
    for (const auto* line : {&from, &to})
      for (const Vec3& x : *line) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
    double sum = 0;
    long count = 0;
    for (int t : state.grid.query(mesh, lo, hi)) {
      if (!state.cuttable[t]) continue;
      const Tet& k = mesh.tets[t];
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          sum += (mesh.nodes[k[i]] - mesh.nodes[k[j]]).norm(), ++count;
    }
    margin = count ? options.front_margin_fraction * sum / count : 0;
  }
  // Extended polylines: beyond tip and heel along the edge, and ahead of the motion. The
  // band's borders in the tissue (the tip's and heel's paths, where a stroke starts) are
  // conformed (split_along_border); its front is conformed when the stroke ends
  // (finish_stroke), and until then the margin ahead lets the cut open close behind the blade.
  auto extend_ends = [margin](std::vector<Vec3> line) {
    const Vec3 down = line.front() - line[1], up = line.back() - line[line.size() - 2];
    if (down.norm() > 0) line.front() += margin * down.normalized();
    if (up.norm() > 0) line.back() += margin * up.normalized();
    return line;
  };
  std::vector<Vec3> a = extend_ends(from), b = extend_ends(to);
  for (size_t i = 0; i < a.size(); ++i) {
    const Vec3 motion = b[i] - a[i];
    if (motion.norm() > 0) b[i] += margin * motion.normalized();
  }
  // Each quad (a_i, a_i+1, b_i+1, b_i) as two triangles, tip side first as a single edge's
  // sweep (A0, B0, B1), (A0, B1, A1).
  std::vector<std::array<Vec3, 3>> sweep;
  std::vector<CutBorder> borders;
  for (size_t i = 0; i + 1 < a.size(); ++i) {
    const int first = static_cast<int>(sweep.size());
    sweep.push_back({a[i], a[i + 1], b[i + 1]});
    sweep.push_back({a[i], b[i + 1], b[i]});
    if (!continues) borders.push_back({first, a[i], a[i + 1]});  // where the stroke starts
  }
  // The paths of the tip and the heel bound the band (from where the last band's paths
  // ended, so they join); its front does not (the next step carries the cut on from there).
  if (!continues) state.border_from = {a.front(), a.back()};
  const Vec3 now[2] = {b.front(), b.back()};
  const int tri[2] = {1, static_cast<int>(sweep.size()) - 2};
  for (int e = 0; e < 2; ++e) {
    borders.push_back({tri[e], state.border_from[e], now[e], e == 0});  // e = 0: the tip's
    state.border_from[e] = now[e];
  }
  const std::vector<std::array<Vec3, 3>> none;
  const Triangles marked_in =
      continues ? spaced_bands(state.last_sweep, state.last_sweep_bands, kBandSpacing * margin)
                : none;
  // A face the band opens may reach only a little ahead of the blade's edge (CutOptions::
  // front_corner_reach), though the tissue is split the whole margin ahead; nor much below the
  // tip's path or above the heel's (path_corner_reach), though it is split the margin past
  // them too.
  BladeStop stop;
  stop.line = extend_ends(to);
  for (size_t i = 0; i < to.size(); ++i) {
    const Vec3 motion = to[i] - from[i];
    stop.past.push_back(motion.norm() > 0 ? Vec3(motion.normalized()) : Vec3::Zero());
  }
  stop.reach = options.front_corner_reach * margin;
  stop.slack_fraction = options.front_corner_slack;
  // The tip's and heel's paths as the blade took them (no margin), each point with the way
  // along the blade past it: down past the tip, up past the heel.
  if (!continues) {
    state.tip_path.clear(), state.tip_past.clear();
    state.heel_path.clear(), state.heel_past.clear();
    state.start_line.clear(), state.start_past.clear();
    // A stroke that begins inside the last one's incision (the blade cuts on after a stroke
    // ended: a region move carried its rest edge a little off the last one's) has that cut
    // behind it, whose faces it may still open.
    bool in_incision = !state.blade_sweep.empty();
    const StrokeSurface last(state.blade_sweep);
    for (const Vec3& x : from) in_incision = in_incision && last.near(x, margin);
    state.start_pending = !in_incision;
  }
  // Where the stroke starts moving across the blade's edge (a blade pressed in first moves
  // along it, and what lies above its heel then is not behind it): behind is against that
  // motion.
  if (state.start_pending) {
    const Vec3 edge = (from.back() - from.front()).normalized();
    std::vector<Vec3> behind;
    for (size_t i = 0; i < from.size(); ++i) {
      const Vec3 motion = to[i] - from[i];
      const Vec3 across = motion - motion.dot(edge) * edge;
      if (!(across.norm() >= kAcrossShare * motion.norm() && motion.norm() > 0)) break;
      behind.push_back(-across.normalized());
    }
    if (behind.size() == from.size()) {
      // Only where there is tissue behind the blade's edge as it starts: a blade that comes
      // in from outside (through the tissue's side, slicing a lobe) passed the skin behind its
      // first band, and the faces there must open or the slice leaves the piece attached.
      for (size_t i = 0; i + 1 < a.size(); ++i)
        for (int k = 0; k <= kStartSamples; ++k) {
          if (k == kStartSamples && i + 2 < a.size()) continue;  // the next segment's first
          const double u = static_cast<double>(k) / kStartSamples;
          const Vec3 x = (1 - u) * a[i] + u * a[i + 1];
          const Vec3 way = ((1 - u) * behind[i] + u * behind[i + 1]).normalized();
          if (tet_containing(mesh, state.grid, x) >= 0 &&
              tet_containing(mesh, state.grid, x + margin * way) >= 0)
            state.start_line.push_back(x), state.start_past.push_back(way);
        }
      state.start_pending = false;
    }
  }
  const auto past_end = [](const Vec3& end, const Vec3& next) {
    const Vec3 d = end - next;
    return d.norm() > 0 ? Vec3(d.normalized()) : Vec3::Zero();
  };
  const size_t heel = to.size() - 1;
  if (state.tip_path.empty()) {
    extend_path(state.tip_path, state.tip_past, from.front(), past_end(from[0], from[1]), 0);
    extend_path(state.heel_path, state.heel_past, from.back(), past_end(from[heel], from[heel - 1]),
                0);
  }
  const double spacing = kBandSpacing * margin;
  extend_path(state.tip_path, state.tip_past, to.front(), past_end(to[0], to[1]), spacing);
  extend_path(state.heel_path, state.heel_past, to.back(), past_end(to[heel], to[heel - 1]),
              spacing);
  state.stroke_margin = margin;
  std::vector<BladeStop> stops;
  if (limits_ahead(options)) stops.push_back(stop);
  add_path_limits(state, options, margin, stops);
  CutResult result = cut_triangles(mesh, state, sweep, options, continues ? state.last_sweep : none,
                                   borders, kSkinCornerSlack, &marked_in, stops);
  Triangles swept;
  for (size_t i = 0; i + 1 < from.size(); ++i) {
    swept.push_back({from[i], from[i + 1], to[i + 1]});
    swept.push_back({from[i], to[i + 1], to[i]});
  }
  keep_in_stroke(state.blade_sweep, swept, continues);
  // The stroke so far (kMaxStrokeTriangles).
  keep_in_stroke(state.last_sweep, sweep, continues, &state.last_sweep_bands);
  state.last_sweep_end = {to.front(), to.back()};
  state.last_band = sweep;
  // Where the blade's edge is (the margin ahead of it is for the next band): the cut ends there.
  state.last_front = std::move(stop.line);
  state.last_front_motion = std::move(stop.past);
  return result;
}

CutResult finish_stroke(TetMesh& mesh, CutState& state, const CutOptions& options) {
  if (state.last_band.empty()) return {};
  std::vector<CutBorder> front;
  for (size_t i = 0; i + 1 < state.last_front.size(); ++i)
    front.push_back({static_cast<int>(2 * i + 1), state.last_front[i], state.last_front[i + 1]});
  const std::vector<std::array<Vec3, 3>> band = std::move(state.last_band);
  state.last_band.clear();
  // The band's own triangles again: its tets are split already, so only the front's are new.
  // No skin slack here: the front is where the blade stopped, and a face reaching past it at
  // the skin would open the tissue ahead of the blade (the end of a curved stroke on a fine
  // liver: open faces 4 x the tolerance past the sweep with it, within tolerance without).
  // Nor may a face reach past the front by more than its corners' slack (CutOptions::
  // front_corner_reach): the front is conformed now, a face beyond it would stay open.
  BladeStop stop;
  stop.line = state.last_front;
  stop.past = state.last_front_motion;
  stop.slack_fraction = 1;
  std::vector<BladeStop> stops;
  if (limits_ahead(options)) stops.push_back(std::move(stop));
  add_path_limits(state, options, state.stroke_margin, stops);
  // The faces the front's split makes behind the last band (a slow stroke's band is a step
  // wide; the front's tets reach farther back) lie along that band's plane, but their centroids
  // lie outside its triangles, and a curved stroke's earlier bands, at an angle, find them off
  // their planes: the band reached back a margin along its motion is cut and marked with it
  // (docs/DESIGN.md section 8, "A stroke's end", eq. (19c)).
  std::vector<std::array<Vec3, 3>> reached = band;
  if (options.end_band_reaches_back && !state.last_front.empty() &&
      band.size() == 2 * (state.last_front.size() - 1)) {
    for (size_t i = 0; i + 1 < state.last_front.size(); ++i) {
      const Vec3 back0 = band[2 * i][0] - state.stroke_margin * state.last_front_motion[i],
                 back1 = band[2 * i][1] - state.stroke_margin * state.last_front_motion[i + 1];
      reached.push_back({back0, back1, band[2 * i][0]});
      reached.push_back({band[2 * i][0], back1, band[2 * i][1]});
    }
  }
  CutResult result =
      cut_triangles(mesh, state, reached, options, state.last_sweep, front, 1.0, nullptr, stops);
  // What only border corners hold shut is opened now: nothing later will (closed_marks.hpp).
  const auto open_marks = [&](const std::vector<int>& tets) {
    const long marked_before = count_marked_face_sides(mesh);
    const size_t changed_before = result.changed_tets.size();
    if (open_closed_marks(mesh, state, tets, options, result) > 0)
      settle(mesh, state, result, changed_before, marked_before);
  };
  if (options.open_closed_marks) open_marks(state.stroke_tets);
  // Where the tip's path meets the front the opened surface may stop an element short of the
  // tip (tip_corner.hpp): filled once the marks have opened what they can, its own marks then
  // opened as the others were.
  if (options.fill_tip_corner) {
    const long marked_before = count_marked_face_sides(mesh);
    const size_t changed_before = result.changed_tets.size();
    if (fill_tip_corner(mesh, state, state.last_sweep_end[0], band, options, result) >= 0) {
      settle(mesh, state, result, changed_before, marked_before);
      if (options.open_closed_marks) {
        std::vector<int> tets = state.stroke_tets;
        tets.insert(tets.end(), result.changed_tets.begin() + static_cast<long>(changed_before),
                    result.changed_tets.end());
        open_marks(tets);
      }
    }
  }
  return result;
}

}  // namespace stc
