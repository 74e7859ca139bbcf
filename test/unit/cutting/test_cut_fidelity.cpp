// Issue 9's figures, measured on the cutter alone (rest coordinates, no solve): for a stroke,
// the swept area inside the operation part (less one element layer at the interface), the open
// cut area on each side of the blade, the two-sided Hausdorff distance between the open cut
// faces and the swept surface, how the walls face, the smallest dihedral angle and the steps
// that moved through tissue yet changed nothing. On the thigh and on TetGen livers (~5k and
// ~50k tets), vertical and 45-degree blades, 0.2 mm and 3 mm steps, straight and curved paths.
#include "common/cut_fidelity_scenes.hpp"

#include "common/cut_measures.hpp"
#include "cutting/cut_sweep.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <memory>
#include <sstream>

namespace stc {
namespace {

using namespace fidelity;

struct Bench {
  std::string name;
  TetMesh mesh;
  CutState state;
  std::unique_ptr<MeasuredRegion> region;
  double volume = 0;
  Stroke stroke;  // the mesh's base stroke (vertical, straight)
  CutOptions options;
};

std::unique_ptr<Bench> make_bench(const std::string& name) {
  auto b = std::make_unique<Bench>();
  b->name = name;
  OperationRegion region;
  region.kind = OperationRegion::Kind::kSphere;
  if (name == "thigh") {
    const Scene scene = make_thigh_scene();
    b->mesh = scene.mesh;
    region = scene.operation_region;
    b->stroke.centre = region.sphere.center + Vec3(0, 0.003, 0);  // off the y = 0 node plane
    b->stroke.up = Vec3::UnitX();
    b->stroke.direction = Vec3::UnitZ();
    b->stroke.length = 0.04;
    b->stroke.depth = 0.012;
  } else {
    const std::string source = name.substr(0, name.find('-'));
    const int tets = std::stoi(name.substr(name.find('-') + 1));
    b->mesh = tetgen_liver(source, tets);
    region.sphere = Sphere{top_node(b->mesh), 0.025};
    b->stroke.centre = region.sphere.center;
    b->stroke.up = Vec3::UnitY();
    b->stroke.direction = Vec3::UnitX();
    b->stroke.length = 0.03;
    b->stroke.depth = 0.01;
  }
  const Partition p = partition_mesh(b->mesh, region);
  std::vector<std::uint8_t> locked(b->mesh.nodes.size(), 0);
  for (int i : p.interface) locked[static_cast<size_t>(i)] = 1;
  b->volume = total_volume(b->mesh);
  b->region = std::make_unique<MeasuredRegion>(b->mesh, p.operation_tet, locked);
  b->state = make_cut_state(b->mesh, locked, p.operation_tet);
  return b;
}

struct Figures {
  CutFidelity f;
  // 3 mm steps: the least share of one step's swept area (in the region, steps sweeping at
  // least a quarter of the mean) within tolerance of an open face - item 1's "no gaps along
  // the path" step by step; 1 where not measured.
  double least_step_covered = 1;
  int steps = 0, through_tissue = 0, changed_nothing = 0;
  double min_dihedral_before = 0, min_dihedral = 0;
  std::vector<std::string> violated;
  std::string line;
};

constexpr double kBladeLength = 0.02;

Figures run_stroke(Bench& b, const Stroke& s, const std::string& label) {
  Figures out;
  out.min_dihedral_before = mesh_quality(b.mesh).min_dihedral_deg;
  const std::vector<BladePose> poses =
      stroke_poses(s, b.mesh.nodes, extract_boundary_surface(b.mesh));
  std::vector<SweptTriangle> sweep;
  for (size_t i = 1; i < poses.size(); ++i) {
    const BladeEdge from = blade_edge(poses[i - 1], kBladeLength),
                    to = blade_edge(poses[i], kBladeLength);
    const CutResult r = cut_sweep(b.mesh, b.state, from, to, b.options);
    const size_t first = sweep.size();
    add_sweep(from, to, sweep);
    ++out.steps;
    // Through tissue: the step's swept triangles reach into the measured region.
    bool tissue = false;
    for (size_t k = first; k < sweep.size() && !tissue; ++k)
      for (double u = 0.05; u < 1 && !tissue; u += 0.1)
        for (double v = 0.05; u + v < 1 && !tissue; v += 0.1)
          tissue = b.region->contains(sweep[k].x[0] + u * (sweep[k].x[1] - sweep[k].x[0]) +
                                      v * (sweep[k].x[2] - sweep[k].x[0]));
    out.through_tissue += tissue;
    if (std::getenv("STC_FIDELITY_VERBOSE"))
      std::printf("  step %zu: tissue %d, split %d, new nodes %zu, moved %zu, faces %d\n", i,
                  tissue ? 1 : 0, r.tets_split, r.new_nodes.size(), r.moved_nodes.size(),
                  r.cut_faces_added);
    if (tissue && r.tets_split == 0 && r.new_nodes.empty() && r.cut_faces_added == 0)
      ++out.changed_nothing;
  }
  {
    const CutResult r =
        finish_stroke(b.mesh, b.state, b.options);  // the blade stops: the stroke ends
    if (std::getenv("STC_FIDELITY_VERBOSE"))
      std::printf("  finish: split %d, new nodes %zu, faces %d\n", r.tets_split, r.new_nodes.size(),
                  r.cut_faces_added);
  }
  // STC_FIDELITY_DUMP=FILE: the sweep triangles (S), open cut faces (C) and marked faces (M),
  // in mm along / up / aside from the stroke's centre, for a plot of where the holes are.
  // STC_FIDELITY_DUMP_TETS=1 adds every tet (T, its four nodes and their positions).
  if (const char* dump = std::getenv("STC_FIDELITY_DUMP"))
    dump_cut(dump, b.mesh, sweep, s.centre, s.direction, s.up,
             std::getenv("STC_FIDELITY_DUMP_TETS") != nullptr);
  out.f = measure_cut_fidelity(*b.region, b.mesh, sweep, 0.25e-3);
  if (s.step > 1e-3) {
    // A step's two triangles (add_sweep).
    const size_t steps = sweep.size() / 2;
    const double mean = out.f.swept_area / static_cast<double>(steps);
    for (size_t k = 0; k < steps; ++k) {
      const double swept = out.f.swept_by_triangle[2 * k] + out.f.swept_by_triangle[2 * k + 1];
      const double covered =
          out.f.covered_by_triangle[2 * k] + out.f.covered_by_triangle[2 * k + 1];
      if (swept >= 0.25 * mean)
        out.least_step_covered = std::min(out.least_step_covered, covered / swept);
    }
  }
  out.min_dihedral = mesh_quality(b.mesh).min_dihedral_deg;
  InvariantLimits limits;
  limits.initial_volume = b.volume;
  out.violated = check_cut_invariants(b.mesh, b.state.origin_volume, limits);
  std::ostringstream line;
  line.precision(3);
  line << b.name << " " << label << ": swept " << out.f.swept_area * 1e4 << " cm2, opened "
       << out.f.opened_area[0] * 1e4 << " / " << out.f.opened_area[1] * 1e4 << " cm2 ("
       << 100 * out.f.opening() << " % the lesser side; "
       << 100 * out.f.covered_area / out.f.swept_area
       << " % of the swept area within tolerance of an open face), Hausdorff "
       << out.f.hausdorff * 1e3 << " mm (faces->sweep " << out.f.faces_to_sweep * 1e3
       << ", sweep->faces " << out.f.sweep_to_faces * 1e3 << "; " << out.f.hausdorff_over_tolerance
       << " x tolerance; faces " << out.f.faces_over_tolerance << " x), wall alignment "
       << out.f.wall_alignment << ", min dihedral " << out.min_dihedral_before << " -> "
       << out.min_dihedral << " deg, " << out.changed_nothing << " of " << out.through_tissue
       << " steps through tissue changed nothing, tets " << b.mesh.num_tets()
       << ", closed cut faces " << test::closed_cut_faces(b.mesh);
  if (s.step > 1e-3) line << ", least step covered " << 100 * out.least_step_covered << " %";
  line << ", walled " << 100 * out.f.walled_area[0] / std::max(out.f.swept_area, 1e-300) << " / "
       << 100 * out.f.walled_area[1] / std::max(out.f.swept_area, 1e-300) << " %";
  {
    // Where the largest hole is: along the path, under the surface.
    const Vec3 w = out.f.worst_swept_point - s.centre;
    line << ", worst hole at " << 1e3 * w.dot(s.direction) << " mm along, " << 1e3 * w.dot(s.up)
         << " mm up from the centre";
    const Vec3 v = out.f.worst_face_point - s.centre;
    line << ", worst face point at " << 1e3 * v.dot(s.direction) << " mm along, "
         << 1e3 * v.dot(s.up) << " mm up, " << 1e3 * v.dot(s.up.cross(s.direction)) << " mm aside";
  }
  out.line = line.str();
  std::printf("FIDELITY %s\n", out.line.c_str());
  return out;
}

Stroke variant(Stroke s, double tilt, double step, bool curved) {
  s.tilt_deg = tilt;
  s.step = step;
  s.radius = curved ? 0.02 : 0;
  return s;
}

// STC_FIDELITY_SHIFT="ALONG ASIDE" (mm): every stroke of the matrices moved so far along its
// direction and across the blade plane - the same strokes on the same mesh, met at other
// crossing points, to see how much of a stroke's figures is the mesh's luck (docs/HISTORY.md,
// stop 50).
Stroke shifted(Stroke s) {
  const char* shift = std::getenv("STC_FIDELITY_SHIFT");
  double along = 0, aside = 0;
  if (shift == nullptr || std::sscanf(shift, "%lf %lf", &along, &aside) != 2) return s;
  s.centre += 1e-3 * (along * s.direction + aside * s.up.cross(s.direction).normalized());
  return s;
}

// Issue 9 items 1 and 2 as stated, for one stroke: each side opens >= 90 % of the swept area,
// every swept point lies within max(0.5 mm, 0.25 h) of an open face and every open face within
// that of the sweep, the walls face along the blade normal, and no step through tissue leaves
// it untouched (3 mm steps).
void expect_issue_targets(const Figures& fig, const Stroke& s) {
  const bool twisted = s.radius > 0 && s.tilt_deg > 0;
  EXPECT_GE(std::min(fig.f.opened_area[0], fig.f.opened_area[1]), 0.9 * fig.f.swept_area)
      << fig.line;
  EXPECT_GE(fig.f.covered_area, 0.99 * fig.f.swept_area) << fig.line;
  EXPECT_LE(fig.f.hausdorff_over_tolerance, 1.0) << fig.line;
  // A tilted blade on a curved path sweeps a twisted surface; its planar pieces meet at
  // creases where the faces lean (measured 0.89-0.91). Elsewhere measured >= 0.94 (the coarse
  // liver2's tilted straight 3 mm stroke: two faces along the tip's path lean 58 deg).
  EXPECT_GE(fig.f.wall_alignment, twisted ? 0.85 : 0.9) << fig.line;
  if (s.step > 1e-3) {
    EXPECT_LE(fig.changed_nothing, 2) << fig.line;
  }
}

enum class Targets { kFloors, kIssue };

// The matrix of issue 9 item 1 on one mesh; each stroke on a fresh copy. Asserted here: the cut
// invariants and floors well under what every configuration measures (a regression guard); the
// issue's own targets (expect_issue_targets) on the meshes where every stroke meets them -
// README lists the rest. Every stroke keeps the shape guard's promise (the default 5 deg since
// stop 51, or any other); a guard above the default is measured against floors of its own.
// STC_FIDELITY_GUARD=DEG runs every matrix with that shape guard (what a guard costs, stroke
// by stroke).
void measure_matrix(const std::string& mesh_name, CutOptions options = {},
                    Targets targets = Targets::kFloors) {
  if (const char* guard = std::getenv("STC_FIDELITY_GUARD"))
    options.split_min_dihedral_deg = std::atof(guard);
  const bool strong_guard = options.split_min_dihedral_deg > CutOptions{}.split_min_dihedral_deg;
  for (bool curved : {false, true})
    for (double tilt : {0.0, 45.0})
      for (double step : {0.2e-3, 3e-3}) {
        std::ostringstream label;
        if (options.split_min_dihedral_deg != CutOptions{}.split_min_dihedral_deg)
          label << (strong_guard ? "shape guard " : "guard ") << options.split_min_dihedral_deg
                << " deg ";
        label << (curved ? "curved" : "straight") << " tilt " << tilt << " step " << step * 1e3
              << " mm";
        if (const char* only = std::getenv("STC_FIDELITY_ONLY"))
          if (label.str().find(only) == std::string::npos) continue;
        auto b = make_bench(mesh_name);
        b->options = options;
        const Stroke stroke = shifted(variant(b->stroke, tilt, step, curved));
        const Figures fig = run_stroke(*b, stroke, label.str());
        EXPECT_TRUE(fig.violated.empty()) << fig.line << ": " << fig.violated.front();
        // The shape guard's promise (docs/DESIGN.md section 8, "Shape guard").
        EXPECT_GE(fig.min_dihedral,
                  std::min(options.split_min_dihedral_deg, fig.min_dihedral_before) - 1e-6)
            << fig.line;
        if (strong_guard) {
          // Floors under what a strong guard measures: the cut costs fidelity where it would
          // have made a sliver.
          EXPECT_GE(fig.f.opening(), 0.85) << fig.line;
          EXPECT_GE(fig.f.covered_area, 0.95 * fig.f.swept_area) << fig.line;
          EXPECT_LE(fig.f.hausdorff_over_tolerance, 3.0) << fig.line;
          continue;
        }
        EXPECT_GT(fig.f.swept_area, 1e-4) << fig.line;  // the stroke is in the tissue
        EXPECT_GE(fig.f.covered_area, 0.25 * fig.f.swept_area) << fig.line;
        EXPECT_GE(fig.f.opening(), 0.1) << fig.line;
        // Conformed borders (stop 27): at most 1.7 measured (thigh straight vertical, the
        // faces past the stroke's end); faces reaching 3/4 of the front margin (stop 28): 1.38
        // (the fine liver2's curved vertical 3 mm stroke).
        EXPECT_LE(fig.f.faces_over_tolerance, 1.6) << fig.line;
        EXPECT_GE(fig.f.wall_alignment, 0.7) << fig.line;
        // The conformed borders (docs/DESIGN.md section 8, "Borders"): a straight vertical
        // stroke opens up to the blade on every mesh, slow or fast, with no hole (the thigh's
        // 3 mm stroke left a 9.4 mm one along the tip's path without them; measured 100 %
        // covered).
        if (!curved && tilt == 0) {
          EXPECT_GE(fig.f.covered_area, 0.99 * fig.f.swept_area) << fig.line;
        }
        // Issue 9 item 1's 90 % on every stroke (stop 37; least 93.2 %, the 12k liver's curved
        // vertical 3 mm stroke). The tilted curved strokes open through their creases since
        // marks hanging on an opened wall's edge are held closed instead of dropped
        // (separation.hpp; the thigh's 3 mm one 74.9 -> 107 %), the slow curved ones up to the
        // tip since nodes on the surface's extension count on a later band's border
        // (cut_state.hpp, on_extension; the thigh's vertical 0.2 mm one 82.6 -> 106 %).
        EXPECT_GE(fig.f.opening(), 0.9) << fig.line;
        // And each wall covers 90 % of the sweep: its open faces lie across (along the blade
        // normal, within the tolerance) from that much of it - the opened area alone may
        // count faces that lean, or lie past the sweep (stop 56: least 93.1 %, the thigh's
        // curved 45-degree 0.2 mm stroke; test_fidelity_measure.cpp checks the ruler).
        for (int side = 0; side < 2; ++side) {
          EXPECT_GE(fig.f.walled_area[side], 0.9 * fig.f.swept_area) << fig.line;
        }
        // No gap along the path, step by step (3 mm steps; measured 96.3-100 %; the thigh's
        // curved 45-degree stroke had a step 11 % covered before stop 37: the 1 cm hole).
        EXPECT_GE(fig.least_step_covered, 0.9) << fig.line;
        if (targets == Targets::kIssue) expect_issue_targets(fig, stroke);
      }
}

TEST(CutFidelity, ThighMatrix) { measure_matrix("thigh"); }
// The two coarse TetGen livers meet issue 9's items 1 and 2 on all eight strokes (stop 46: the
// 12k liver since the limit on how far ahead of the blade a face opens, CutOptions::
// front_corner_reach).
TEST(CutFidelity, Liver2CoarseMeetsIssueTargets) {
  measure_matrix("liver2-5000", {}, Targets::kIssue);
}
TEST(CutFidelity, LiverBoundaryCoarseMeetsIssueTargets) {
  measure_matrix("liver-5000", {}, Targets::kIssue);
}
TEST(CutFidelity, Liver2Fine) { measure_matrix("liver2-50000"); }
TEST(CutFidelity, LiverBoundaryFine) { measure_matrix("liver-50000"); }

// The smallest dihedral angle of the cuttable tets (the operation part less its interface layer).
double cuttable_min_dihedral(const Bench& b) {
  return test::tet_shapes(b.mesh, b.state.cuttable).least;
}

// The shape guard on one stroke (cheap enough for the sanitized CI run): the coarse liver2's
// straight vertical 3 mm stroke leaves its cuttable tets at min(5 deg, their smallest before)
// with the guard (measured 4.51 -> 4.51 deg, the uncut part's own) and well under it without
// (4.51 -> 0.78 deg), and still opens the sweep.
TEST(CutFidelity, ShapeGuardOnOneStroke) {
  for (const double guard : {5.0, 0.0}) {
    auto b = make_bench("liver2-5000");
    b->options.split_min_dihedral_deg = guard;
    const double before = cuttable_min_dihedral(*b);
    const Figures fig = run_stroke(*b, variant(b->stroke, 0, 3e-3, false),
                                   guard > 0 ? "one stroke, shape guard" : "one stroke, no guard");
    const double after = cuttable_min_dihedral(*b);
    std::printf("  cuttable tets' smallest dihedral angle %.2f -> %.2f deg\n", before, after);
    EXPECT_TRUE(fig.violated.empty()) << fig.line;
    EXPECT_GE(fig.f.opening(), 0.9) << fig.line;
    if (guard > 0) {
      EXPECT_GE(after, std::min(guard, before) - 1e-6) << fig.line;
    } else {
      EXPECT_LT(after, 0.5 * std::min(5.0, before)) << fig.line;
    }
  }
}

// CutOptions::open_closed_marks (cutting/closed_marks.hpp): the marks a stroke's end holds shut
// because all their corners lie on the cut's border get a node inside the cut and open. The
// 12k TetGen liver's 45-degree straight 3 mm stroke: measured 0.88 -> 0.69 x the Hausdorff
// tolerance, 94.8 -> 95.9 % opened; over the 40 strokes of the matrix 213 -> 121 closed cut
// faces, the least opening 93.2 -> 95.5 %, the summed excess over the tolerance 6.29 -> 5.38.
TEST(CutFidelity, OpeningClosedMarksAtAStrokesEnd) {
  Figures with, without;
  int closed_with = 0, closed_without = 0;
  for (const bool open : {false, true}) {
    auto b = make_bench("liver-5000");
    b->options.open_closed_marks = open;
    const Figures fig = run_stroke(*b, variant(b->stroke, 45, 3e-3, false),
                                   open ? "closed marks opened" : "closed marks kept");
    EXPECT_TRUE(fig.violated.empty()) << fig.line;
    (open ? with : without) = fig;
    (open ? closed_with : closed_without) = test::closed_cut_faces(b->mesh);
  }
  EXPECT_LT(closed_with, closed_without) << with.line;
  EXPECT_LE(with.f.hausdorff_over_tolerance, 0.9 * without.f.hausdorff_over_tolerance)
      << with.line << "\n"
      << without.line;
  EXPECT_GE(with.f.opening(), without.f.opening()) << with.line << "\n" << without.line;
}

// One stroke on a fresh copy of `mesh` with the cutter's options as they are and again with
// `turn_off` applied to them: what an option does, measured on the same stroke.
struct OnAndOff {
  Figures on, off;
  Stroke stroke;
};
// along, aside: the stroke moved so far (mm) as STC_FIDELITY_SHIFT moves it.
OnAndOff on_and_off(const std::string& mesh, double tilt, double step, bool curved,
                    const std::function<void(CutOptions&)>& turn_off, const char* on_label,
                    const char* off_label, double along = 0, double aside = 0,
                    const std::function<void(CutOptions&)>& both = nullptr) {
  OnAndOff r;
  for (const bool on : {true, false}) {
    auto b = make_bench(mesh);
    if (both) both(b->options);
    if (!on) turn_off(b->options);
    r.stroke = variant(b->stroke, tilt, step, curved);
    r.stroke.centre += 1e-3 * (along * r.stroke.direction +
                               aside * r.stroke.up.cross(r.stroke.direction).normalized());
    const Figures fig = run_stroke(*b, r.stroke, on ? on_label : off_label);
    EXPECT_TRUE(fig.violated.empty()) << fig.line;
    (on ? r.on : r.off) = fig;
  }
  return r;
}

// CutOptions::front_corner_reach: a face the band opens reaches little ahead of the blade's
// edge, so none is left open past where the blade stops. The fine liver2's straight vertical
// 3 mm stroke: without the limit a face with a corner 1.19 mm past the blade's last position
// stays open (measured 1.32 x the tolerance), with it 0.92 x; over the 40 strokes of the matrix
// 22 -> 30 within the tolerance, the least opening 95.5 -> 95.9 %.
TEST(CutFidelity, FacesStopWhereTheBladeStops) {
  const OnAndOff r = on_and_off(
      "liver2-50000", 0, 3e-3, false, [](CutOptions& o) { o.front_corner_reach = -1; },
      "faces limited ahead", "faces not limited ahead");
  EXPECT_LE(r.on.f.faces_over_tolerance, 1.0) << r.on.line;
  EXPECT_GT(r.off.f.faces_over_tolerance, 1.2) << r.off.line;
  EXPECT_GE(r.on.f.opening(), 0.9) << r.on.line;
}

// CutOptions::path_corner_reach: a face the band opens reaches little below the path the tip
// took, though the band is split a front margin below it. The fine liver's tilted straight 3 mm
// stroke: without the limit faces open with a corner up to 1.87 mm under the tip's path
// (1.18 x the tolerance), with it 0.94 x; over the 40 strokes of the matrix (with the faces
// tested again as the blade moves on) 30 -> 33 within the tolerance.
TEST(CutFidelity, FacesStopAtTheTipsPath) {
  const OnAndOff r = on_and_off(
      "liver-50000", 45, 3e-3, false, [](CutOptions& o) { o.path_corner_reach = -1; },
      "faces limited at the tip", "faces not limited at the tip");
  expect_issue_targets(r.on, r.stroke);
  EXPECT_GT(r.off.f.faces_over_tolerance, 1.1) << r.off.line;
}

// CutOptions::path_border_snap: along the tip's path a curved stroke's band is conformed
// through edges from nodes near its plane too (between two bands' planes such a node is "on"
// neither, and the edges from it were left whole: a hole above the tip's path). The fine
// liver2's curved vertical 3 mm stroke: 1.21 x the Hausdorff tolerance without (a hole 2.3 mm
// across at the tip's path), 0.73 x with; over the 40 strokes of the matrix 33 -> 34 within the
// tolerance, the summed excess 2.33 -> 1.87, the worst stroke 1.71 -> 1.53 x (stop 48). Since
// the 5 deg guard moves refused crossings along their edges (stop 51) that stroke measures
// 0.99 x either way (its hole is conformed by the border's shifted crossings); the rule must
// still not cost it.
TEST(CutFidelity, CurvedStrokesConformAlongTheTipsPath) {
  const OnAndOff r = on_and_off(
      "liver2-50000", 0, 3e-3, true, [](CutOptions& o) { o.path_border_snap = 0; },
      "path border with near nodes", "path border without near nodes");
  expect_issue_targets(r.on, r.stroke);
  EXPECT_LE(r.on.f.hausdorff_over_tolerance, r.off.f.hausdorff_over_tolerance + 0.05)
      << r.on.line << "\n"
      << r.off.line;
}

// CutOptions::fill_tip_corner (cutting/tip_corner.hpp): where the tip's path meets the front
// at a stroke's end the opened surface stopped an element short of the tip - on the thigh's
// curved 45-degree 3 mm stroke no face came within 4.2 mm of where the tip stopped (1.52 x the
// Hausdorff tolerance), the corner's tets a fan around an edge almost on the blade's plane. A
// node there and the triangle from it to the opened wall's edge, opened at the stroke's end:
// 3.06 mm (1.12 x; the last third of the triangle stays shut where the shape guard refuses its
// split). The new tets keep the 5 deg guard.
// Since stop 55 the tip's border follows the path the tip took (CutOptions::tip_border_on_path)
// and the corner opens short on fewer strokes: measured here with the border on the band's
// segment, where this one still does (stop 56 fills corners on others, below).
TEST(CutFidelity, TheTipsCornerFillsAtAStrokesEnd) {
  const OnAndOff r = on_and_off(
      "thigh", 45, 3e-3, true, [](CutOptions& o) { o.fill_tip_corner = false; },
      "tip's corner filled", "tip's corner not filled", 0, 0,
      [](CutOptions& o) { o.tip_border_on_path = false; });
  EXPECT_LE(r.on.f.sweep_to_faces, 0.8 * r.off.f.sweep_to_faces) << r.on.line << "\n" << r.off.line;
  EXPECT_LE(r.on.f.hausdorff_over_tolerance, r.off.f.hausdorff_over_tolerance - 0.3)
      << r.on.line << "\n"
      << r.off.line;
  EXPECT_GE(r.on.min_dihedral,
            std::min(CutOptions{}.split_min_dihedral_deg, r.on.min_dihedral_before) - 1e-6)
      << r.on.line;
  EXPECT_GE(r.on.f.opening(), 0.9) << r.on.line;
}

// The tip's corner filled once the stroke's end has opened what it can, hung on any mark facing
// the tip (stop 56; before, the fill came first and only opened walls counted). The thigh's
// curved 45-degree 0.2 mm stroke moved 0.5 mm on and 0.5 mm aside: the opened surface stopped
// 5 mm short of the tip (1.73 x the Hausdorff tolerance, as without the fill), 0.92 x now.
TEST(CutFidelity, TheTipsCornerFillsAfterTheMarksOpen) {
  const OnAndOff r = on_and_off(
      "thigh", 45, 0.2e-3, true, [](CutOptions& o) { o.fill_tip_corner = false; },
      "corner filled last", "corner not filled", 0.5, -0.5);
  EXPECT_LE(r.on.f.hausdorff_over_tolerance, 1.0) << r.on.line;
  EXPECT_GT(r.off.f.hausdorff_over_tolerance, 1.3) << r.off.line;
  EXPECT_GE(r.on.f.opening(), 0.9) << r.on.line;
}

// CutOptions::tip_corner_from_node (cutting/tip_corner.hpp, eq. (19d')): where a new node at
// the tip would make tets too thin, a node of the cut within a front margin of it becomes the
// corner, the tets the triangle from it passes through retriangulated as its star. The thigh's
// curved vertical 0.2 mm stroke moved 0.5 mm back and 0.5 mm aside: the opened surface short of
// the tip (1.38 x the Hausdorff tolerance) without it, 0.86 x with it. The star's tets keep the 5
// deg guard.
TEST(CutFidelity, TheTipsCornerFillsFromANodeOfTheCut) {
  const OnAndOff r = on_and_off(
      "thigh", 0, 0.2e-3, true, [](CutOptions& o) { o.tip_corner_from_node = false; },
      "corner from a node", "corner from no node", -0.5, -0.5);
  EXPECT_LE(r.on.f.hausdorff_over_tolerance, 1.0) << r.on.line;
  EXPECT_GT(r.off.f.hausdorff_over_tolerance, 1.2) << r.off.line;
  EXPECT_GE(r.on.min_dihedral,
            std::min(CutOptions{}.split_min_dihedral_deg, r.on.min_dihedral_before) - 1e-6)
      << r.on.line;
  EXPECT_GE(r.on.f.opening(), 0.9) << r.on.line;
}

// CutOptions::open_marks_at_input_scale (cutting/closed_marks.hpp): a closed mark split small
// near the tip's path counts as along the blade's sweep at the scale of the input tet it came
// from, so the stroke's end opens it. Over issue 9's 200 shifted strokes 149 -> 156 within the
// tolerance (stop 50), 168 -> 169 since the tip's border follows its path (stop 55, summed
// excess 11.29 -> 9.73). The thigh's straight 45-degree 3 mm stroke moved 0.5 mm back and
// 0.5 mm aside: a hole 3.27 mm across at the tip's path without (1.16 x the tolerance), 1.33 mm
// with (0.69 x). (The fine liver's curved vertical 3 mm stroke this was measured on up to stop
// 54 opens the same either way since then.)
TEST(CutFidelity, ClosedMarksAtTheTipsPathOpen) {
  const OnAndOff r = on_and_off(
      "thigh", 45, 3e-3, false, [](CutOptions& o) { o.open_marks_at_input_scale = false; },
      "marks at the input's scale", "marks at their own scale", -0.5, -0.5);
  EXPECT_LE(r.on.f.sweep_to_faces, 0.85 * r.off.f.sweep_to_faces) << r.on.line << "\n"
                                                                  << r.off.line;
  EXPECT_GE(r.on.f.opening(), 0.9) << r.on.line;
}

// CutOptions::opening_split_shift: an opening split the guard refuses at an edge's midpoint is
// made at the nearest place it allows. Measured up to stop 54 on the fine liver's straight
// vertical slow stroke (1.06 x the tolerance without, 0.90 x with), which since the tip's border
// follows its path (stop 55) opens the same either way; now on its curved 45-degree slow stroke:
// a hole 4.42 mm across without (2.76 x), 0.72 mm with (0.86 x).
TEST(CutFidelity, OpeningSplitsMoveAlongTheirEdge) {
  const OnAndOff r = on_and_off(
      "liver-50000", 45, 0.2e-3, true, [](CutOptions& o) { o.opening_split_shift = false; },
      "opening splits moved", "opening splits at midpoints");
  EXPECT_LE(r.on.f.hausdorff_over_tolerance, r.off.f.hausdorff_over_tolerance - 0.1)
      << r.on.line << "\n"
      << r.off.line;
  expect_issue_targets(r.on, r.stroke);
}

// CutOptions::tip_border_on_path: the band is conformed along the path the tip took, not along
// its margin-extended border segment (a front margin below the tip, in a direction a slow
// stroke's 0.2 mm step leaves to the skin's facets). The thigh's straight vertical slow stroke:
// faces 2.56 mm past the sweep along the whole tip without (0.90 x the tolerance), 1.39 mm with
// (0.46 x); over issue 9's 200 shifted strokes 163 -> 169 within the tolerance.
TEST(CutFidelity, TheTipsBorderFollowsItsPath) {
  const OnAndOff r = on_and_off(
      "thigh", 0, 0.2e-3, false, [](CutOptions& o) { o.tip_border_on_path = false; },
      "tip's border on its path", "tip's border on the band's segment");
  expect_issue_targets(r.on, r.stroke);
  EXPECT_LE(r.on.f.faces_over_tolerance, 0.6) << r.on.line;
  EXPECT_GE(r.off.f.faces_over_tolerance, 0.8) << r.off.line;
}

// CutOptions::start_corner_limit: no face opens with a corner more than its slack behind where
// the stroke started, at the skin either (whose corners may otherwise lie 4 x their slack off
// the stroke's surface). The fine liver's curved 45-degree 3 mm stroke moved 0.5 mm back and
// 0.5 mm aside: without the limit a face with a skin corner 3.2 mm behind the start opened
// (2.27 x the tolerance), with it 0.86 x; over issue 9's 200 shifted strokes 159 -> 163 within
// the tolerance, summed excess 9.87 -> 7.61.
TEST(CutFidelity, FacesStopWhereTheStrokeStarted) {
  const OnAndOff r = on_and_off(
      "liver-50000", 45, 3e-3, true, [](CutOptions& o) { o.start_corner_limit = false; },
      "faces limited behind the start", "faces not limited behind the start", -0.5, 0.5);
  EXPECT_LE(r.on.f.faces_over_tolerance, 1.0) << r.on.line;
  EXPECT_GT(r.off.f.faces_over_tolerance, 1.5) << r.off.line;
  expect_issue_targets(r.on, r.stroke);
}

// CutOptions::relocate_refused: where the guards refuse a split and no move along the edge
// passes, the end nearest the blade's plane is moved onto it where its star allows, instead of
// snapped in place up to half an edge off it. The coarse liver2's tilted straight slow stroke
// moved 0.5 mm forward and 0.5 mm aside: the lesser side opened 89.1 % of the sweep with snaps
// alone, 128 % with the moves.
TEST(CutFidelity, RefusedSplitsMoveTheirEndOntoTheBlade) {
  const OnAndOff r = on_and_off(
      "liver2-5000", 45, 0.2e-3, false, [](CutOptions& o) { o.relocate_refused = false; },
      "refused ends moved", "refused ends snapped", -0.5, -0.5);
  EXPECT_GE(r.on.f.opening(), r.off.f.opening() + 0.2) << r.on.line << "\n" << r.off.line;
  expect_issue_targets(r.on, r.stroke);
}

// A tilted blade's stroke opens from where it starts: the faces that straddle its start are
// refused while the blade is short of their far corners (CutOptions::front_corner_reach) and
// tested again as it moves on (mark_deferred_faces), and a node snapped onto the plane past the
// start is on the stroke, so that later steps find them too. Stop 46 measured holes there of
// 1.30 x (the thigh) and 1.50 x (the fine liver) the tolerance on these slow strokes.
TEST(CutFidelity, TiltedStrokesOpenFromTheirStart) {
  for (const std::string mesh : {"thigh", "liver-50000"}) {
    auto b = make_bench(mesh);
    const Stroke stroke = variant(b->stroke, 45, 0.2e-3, false);
    const Figures fig = run_stroke(*b, stroke, "tilted, from its start");
    EXPECT_TRUE(fig.violated.empty()) << fig.line;
    expect_issue_targets(fig, stroke);
  }
}

// The matrix with the shape guard at 1 deg (the default of stops 44-50, and what a mesh without
// a quality bound is given, docs/SCENE.md): no stroke leaves a tet under min(1 deg, the mesh's
// smallest before), and every floor of the default holds. Measured on all five meshes at five
// positions (stop 51): 148 of 200 strokes within the Hausdorff tolerance, 149 at 5 deg. The
// thigh and the coarse liver here (the fine meshes cost a minute more).
TEST(CutFidelity, OneDegreeGuardMatrix) {
  CutOptions options;
  options.split_min_dihedral_deg = 1;
  measure_matrix("thigh", options);
  measure_matrix("liver2-5000", options);
}

}  // namespace
}  // namespace stc
