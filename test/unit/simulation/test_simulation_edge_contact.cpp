// The whole blade touches the tissue (issue 14), through the simulation, on the thigh and on
// a TetGen liver (sofa_liver2.obj tetrahedralized, scaled to 15 cm): a flat blade lowered
// indents a line that equals the full model with the same imposed nodes; the wrench's torque
// is r x F summed over the held nodes (reactions from the full model); a belly cut with the
// tip outside presses, yields and opens the swept area; no cut while cutting is disabled;
// sliding through its own incision stops cutting and a fresh press cuts again.
#include "common/cut_measures.hpp"
#include "soft_tissue_cutting/assembly/element_cache.hpp"
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/collision/surface_bvh.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace stc {
using test::open_cut_area;
namespace {

// A point of the skin inside the operation region, its outward normal and a tangent to lay
// the blade along.
struct Site {
  Vec3 point, normal, along;
};

struct TestScene {
  Scene scene;
  Site site;
};

TestScene thigh() {
  TestScene t{make_thigh_scene(), {}};
  t.scene.trajectory.clear();
  t.scene.solver.tolerance = 1e-12;
  // The outer wall at theta = 0, mid-length, off the y = 0 node plane; the tube's axis is z.
  t.site = Site{Vec3(0.06, 0.003, 0.048), Vec3::UnitX(), Vec3::UnitZ()};
  return t;
}

// sofa_liver2.obj through TetGen (coarsened for test speed), scaled to 15 cm, the 10 %
// lowest-x nodes fixed, an operation ball of 4 cm around its highest skin node.
TestScene liver() {
  TestScene t;
  Scene& s = t.scene;
  s.source = "sofa_liver2.obj";
  MeshReadOptions options;
  options.tetgen_switches = "pq1.4/10Q";
  s.mesh = read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/sofa_liver2.obj", options);
  Vec3 lo = s.mesh.nodes[0], hi = lo;
  for (const Vec3& x : s.mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const double scale = 0.15 / (hi - lo).maxCoeff();
  for (Vec3& x : s.mesh.nodes) x = (x - lo) * scale;
  hi = (hi - lo) * scale;
  lo.setZero();
  s.material = Material{3000.0, 0.45, 1000.0};
  NodeSelector fixed;
  fixed.kind = NodeSelector::Kind::kBox;
  fixed.box = Box{Vec3::Constant(-1), Vec3(0.1 * hi.x(), 1, 1)};
  s.fixed.push_back(fixed);
  const BoundarySurface skin = extract_boundary_surface(s.mesh);
  std::vector<Vec3> normal(s.mesh.nodes.size(), Vec3::Zero());
  for (const auto& tri : skin.triangles) {
    const Vec3 &a = s.mesh.nodes[tri.nodes[0]], &b = s.mesh.nodes[tri.nodes[1]],
               &c = s.mesh.nodes[tri.nodes[2]];
    for (int v : tri.nodes) normal[v] += (b - a).cross(c - a);
  }
  // The highest skin node in the middle third along x (away from the supports).
  int top = -1;
  for (const auto& tri : skin.triangles)
    for (int v : tri.nodes) {
      const Vec3& x = s.mesh.nodes[v];
      if (x.x() > hi.x() / 3 && x.x() < 2 * hi.x() / 3 &&
          (top < 0 || x.y() > s.mesh.nodes[top].y()))
        top = v;
    }
  const Vec3 n = normal[top].normalized();
  t.site = Site{s.mesh.nodes[top], n, (Vec3::UnitX() - n.x() * n).normalized()};
  s.operation_region.kind = OperationRegion::Kind::kSphere;
  s.operation_region.sphere = Sphere{t.site.point, 0.04};
  s.scalpel = ScalpelParams{0.02, 0.5};
  s.solver = SolverParams{Backend::kCpu, 1e-12, 4000};
  return t;
}

// The blade pose with its edge along `edge_dir` and its body on the `outward` side.
BladePose blade(const Vec3& tip, const Vec3& edge_dir, const Vec3& outward) {
  Eigen::Matrix3d r;
  const Vec3 x = edge_dir.normalized();
  const Vec3 z = (outward - outward.dot(x) * x).normalized();
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  BladePose p;
  p.position = tip;
  p.orientation = Eigen::Quaterniond(r);
  return p;
}

// A blade laid along the site's tangent, `slope` = sin(angle) with the heel deeper, whose
// middle is over the site point at `height` above it (along the normal), shifted by `slide`
// along the tangent.
BladePose laid(const Site& site, double slope, double height, double slide, double length = 0.02) {
  const Vec3 d = std::sqrt(1 - slope * slope) * site.along - slope * site.normal;
  const Vec3 middle = site.point + height * site.normal + slide * site.along;
  return blade(middle - 0.5 * length * d, d, site.normal);
}

// max |u - u_full| / max |u_full| over the nodes the hybrid model solves (not Q), with the
// contact nodes imposed as the simulation held them; and the full model's reactions there.
struct FullCheck {
  double error = 0;
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
};
FullCheck against_full_model(const Simulation& sim, const StepStats& s, const Vec3& tip) {
  const HybridModel& h = sim.model();
  const ElementStiffnessCache cache(h.mesh(), h.material());
  const FullModel full = assemble_full_model(h.mesh(), cache, h.loads(), h.fixed_nodes());
  Vector x = Vector::Zero(full.K.rows());
  std::vector<std::uint8_t> constrained(static_cast<size_t>(x.size()), 0);
  for (int node : s.contact_nodes)
    for (int c = 0; c < 3; ++c) {
      const int row = full.dofs.row_of[static_cast<size_t>(3 * node + c)];
      if (row >= 0) x[row] = h.displacement()[3 * node + c], constrained[row] = 1;
    }
  solve_direct(full.K, full.f, x, constrained);
  const Vector reaction = full.K * x - full.f;
  FullCheck out;
  double ref = 0;
  for (int r = 0; r < full.dofs.rows(); ++r) {
    const int g = full.dofs.global_of[static_cast<size_t>(r)];
    if (h.partition().node_set[static_cast<size_t>(g / 3)] == NodeSet::kInterior) continue;
    out.error = std::max(out.error, std::abs(h.displacement()[g] - x[r]));
    ref = std::max(ref, std::abs(x[r]));
  }
  out.error /= ref;
  for (int node : s.contact_nodes) {
    Vec3 f = Vec3::Zero(), at = h.mesh().nodes[node];
    for (int c = 0; c < 3; ++c) {
      const int row = full.dofs.row_of[static_cast<size_t>(3 * node + c)];
      if (row >= 0) f[c] = reaction[row], at[c] += x[row];
    }
    out.force -= f;
    out.torque += (at - tip).cross(-f);
  }
  return out;
}

// A blade lowered from 1 mm above the site to `depth` below it in 0.05 mm steps, cutting
// off: laid at `slope` (0 = flat), or (slope < 0) standing on its tip.
struct Press {
  std::vector<std::pair<double, double>> curve;  // depth (m), |F| (N)
  double max_jump = 0, error = 0;
  StepStats last;
};
Press press(const TestScene& t, double slope, double depth) {
  Simulation sim(t.scene);
  sim.set_cutting_enabled(false);
  Press out;
  const double step = 5e-5;
  double previous_force = 0;
  for (int k = 0; k * step <= depth + 1e-3 + 1e-12; ++k) {
    const double height = 1e-3 - k * step;
    const BladePose p = slope >= 0 ? laid(t.site, slope, height, 0)
                                   : blade(t.site.point + height * t.site.normal, t.site.normal,
                                           t.site.along);  // a tip press
    out.last = sim.step(p);
    EXPECT_TRUE(out.last.converged);
    const double f = out.last.contact_force.norm();
    out.curve.emplace_back(-height, f);
    if (k > 0) out.max_jump = std::max(out.max_jump, std::abs(f - previous_force));
    previous_force = f;
    EXPECT_FALSE(out.last.cutting);
  }
  return out;
}

void flat_blade_matches_the_full_model(const TestScene& t, const char* what) {
  Simulation sim(t.scene);
  sim.set_cutting_enabled(false);
  StepStats s;
  BladePose p;
  for (int k = 0; k <= 60; ++k) {
    p = laid(t.site, 0.0, 1e-3 - k * 5e-5, 0);
    s = sim.step(p);
    ASSERT_TRUE(s.converged);
  }
  // A line of held nodes along the blade, each at the blade's depth (2 mm below the site).
  ASSERT_GE(s.contact_nodes.size(), 3u) << what;
  const Vec3 tip = p.position;
  const Vec3 e = p.orientation * Vec3::UnitX();
  double first = 1, last = -1;
  for (size_t k = 0; k < s.contact_nodes.size(); ++k) {
    const Vec3 q = s.contact_points[k];
    const double along = (q - tip).dot(e);
    first = std::min(first, along), last = std::max(last, along);
    const Vec3 r = q - (tip + along * e);
    const Vec3 sideways = e.cross(t.site.normal).normalized();
    EXPECT_NEAR((r - r.dot(sideways) * sideways).norm(), 0, 2e-4) << what;  // on the line
  }
  EXPECT_GT(last - first, 0.01) << what << ": the held line spans the blade";
  const FullCheck full = against_full_model(sim, s, tip);
  EXPECT_LT(full.error, 1e-9) << what;
  EXPECT_LT((full.force - s.contact_force).norm(), 1e-9 * full.force.norm()) << what;
  EXPECT_LT((full.torque - s.contact_torque).norm(), 1e-9 * full.torque.norm()) << what;
  // The tissue pushes the blade out, and off-centre from the tip: a real torque ~ F L / 2.
  EXPECT_GT(s.contact_force.dot(t.site.normal), 0.8 * s.contact_force.norm()) << what;
  EXPECT_GT(s.contact_torque.norm(), 0.2 * 0.02 * s.contact_force.norm()) << what;
  std::printf(
      "%s flat blade 2 mm: %zu held nodes, |F| = %.4f N, |torque| = %.3g N m, "
      "full-model error %.2g\n",
      what, s.contact_nodes.size(), s.contact_force.norm(), s.contact_torque.norm(), full.error);
}

TEST(SimulationEdgeContact, FlatBladeIndentsALineEqualToTheFullModelOnTheThigh) {
  flat_blade_matches_the_full_model(thigh(), "thigh");
}
TEST(SimulationEdgeContact, FlatBladeIndentsALineEqualToTheFullModelOnTheLiver) {
  flat_blade_matches_the_full_model(liver(), "liver");
}

// Area of the union of the sweeps (all in one plane), inside the rest tissue, by sampling
// the plane every 0.1 mm.
double swept_area_inside(const std::vector<BladePose>& poses, double length, const TetMesh& rest) {
  if (poses.size() < 2) return 0;
  SurfaceBvh bvh;
  bvh.build(rest, {}, {});
  std::vector<std::array<Vec3, 3>> tris;
  for (size_t k = 1; k < poses.size(); ++k) {
    const Vec3 a0 = poses[k - 1].position,
               b0 = a0 + length * (poses[k - 1].orientation * Vec3::UnitX());
    const Vec3 a1 = poses[k].position, b1 = a1 + length * (poses[k].orientation * Vec3::UnitX());
    tris.push_back({a0, b0, b1});
    tris.push_back({a0, b1, a1});
  }
  // The plane: through the first tip, spanned by the blade's x and z.
  const Vec3 o = poses[0].position, ex = poses[0].orientation * Vec3::UnitX(),
             ez = poses[0].orientation * Vec3::UnitZ();
  double u0 = 1, u1 = -1, v0 = 1, v1 = -1;
  for (const auto& t : tris)
    for (const Vec3& p : t) {
      u0 = std::min(u0, (p - o).dot(ex)), u1 = std::max(u1, (p - o).dot(ex));
      v0 = std::min(v0, (p - o).dot(ez)), v1 = std::max(v1, (p - o).dot(ez));
    }
  const double h = 1e-4;
  double area = 0;
  for (double u = u0 + h / 2; u < u1; u += h)
    for (double v = v0 + h / 2; v < v1; v += h) {
      const Vec3 p = o + u * ex + v * ez;
      bool swept = false;
      for (const auto& t : tris) {
        const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
        if (n.squaredNorm() == 0) continue;
        const double w0 = (t[2] - t[1]).cross(p - t[1]).dot(n),
                     w1 = (t[0] - t[2]).cross(p - t[2]).dot(n),
                     w2 = (t[1] - t[0]).cross(p - t[0]).dot(n);
        if (w0 >= 0 && w1 >= 0 && w2 >= 0) {
          swept = true;
          break;
        }
      }
      if (swept && bvh.contains(p)) area += h * h;
    }
  return area;
}

struct Belly {
  bool pressed = false, yielded = false;
  double peak_force = 0, opened = 0, swept = 0;
  int cuts = 0, cut_steps = 0;
};

// The belly cut: the blade laid at slope 0.6 (37 deg, heel deeper), tip outside, lowered
// 11 mm until its heel is 10 mm below the site's tangent plane and its tip 2 mm above it
// (the thigh's operation tets are ~1.3 cm: a shallower cut splits tets but opens no face),
// drawn 20 mm tip first, lifted out.
constexpr int kLowering = 110;
constexpr double kBellyCutPressure = 0.1;  // N
Belly belly_cut(TestScene t, bool cutting, const char* what) {
  // The belly holds only the few skin nodes under it (8 mm apart on the thigh's skin): it
  // yields at a lower force than the scenes' default 0.5 N would ask.
  t.scene.scalpel.cut_pressure = kBellyCutPressure;
  Simulation sim(t.scene);
  sim.set_cutting_enabled(cutting);
  SurfaceBvh rest;
  rest.build(t.scene.mesh, {}, {});
  std::vector<BladePose> path;
  for (int k = 0; k <= kLowering; ++k) path.push_back(laid(t.site, 0.6, 7e-3 - k * 1e-4, 0));
  for (int k = 1; k <= 20; ++k) path.push_back(laid(t.site, 0.6, -4e-3, -1e-3 * k));
  for (int k = 1; k <= 24; ++k) path.push_back(laid(t.site, 0.6, -4e-3 + 5e-4 * k, -0.02));
  Belly out;
  std::vector<BladePose> after_yield;
  double previous = 0;
  bool rising = true;
  for (size_t k = 0; k < path.size(); ++k) {
    const BladePose& p = path[k];
    EXPECT_FALSE(rest.contains(p.position)) << what << ": the tip stays outside";
    if (out.yielded) after_yield.push_back(p);
    const StepStats s = sim.step(p);
    EXPECT_TRUE(s.converged) << what;
    if (s.in_contact && !out.yielded) {
      out.pressed = true;
      if (k <= kLowering) rising &= s.contact_force.norm() >= previous - 1e-12;  // while lowering
      previous = s.contact_force.norm();
      out.peak_force = std::max(out.peak_force, s.contact_force.norm());
      if (cutting && s.contact_force.norm() > t.scene.scalpel.cut_pressure) {
        out.yielded = true;
        after_yield.push_back(p);
      }
    }
    out.cut_steps += s.cutting;
  }
  EXPECT_TRUE(rising) << what << ": pressing deeper pushes back harder";
  out.cuts = sim.counts().cuts;
  out.opened = 0.5 * open_cut_area(sim.mesh());
  out.swept = swept_area_inside(after_yield, t.scene.scalpel.blade_length, t.scene.mesh);
  InvariantLimits limits;
  limits.initial_volume = sim.counts().volume_initial;
  const auto broken = check_cut_invariants(sim.mesh(), sim.tet_size_classes(), limits);
  EXPECT_TRUE(broken.empty()) << what << ": " << broken.front();
  std::printf(
      "%s belly cut%s: peak force %.3f N, %d cut steps, opened %.1f mm^2 of %.1f mm^2 "
      "swept inside (%.1f %%)\n",
      what, cutting ? "" : " (cutting off)", out.peak_force, out.cut_steps, out.opened * 1e6,
      out.swept * 1e6, out.swept > 0 ? 100 * out.opened / out.swept : 0.0);
  return out;
}

void belly_cut_opens_the_swept_area(const TestScene& t, double opened_fraction, const char* what) {
  const Belly b = belly_cut(t, true, what);
  EXPECT_TRUE(b.pressed) << what;
  EXPECT_TRUE(b.yielded) << what;
  EXPECT_GT(b.cut_steps, 10) << what;
  EXPECT_GT(b.swept, 5e-5) << what;  // > 50 mm^2: a real incision
  // The issue asks >= 90 % of the swept area; how much of a sweep opens is the cut
  // insertion's fidelity (cutting/, docs/DESIGN.md section 8). The thigh's operation tets are
  // ~1.3 cm against a 1 cm deep cut: the cut's borders (the heel's path, where the stroke
  // starts and ends) are conformed, or the tets they run through stay closed (66 % before).
  EXPECT_GE(b.opened, opened_fraction * b.swept) << what;
  // And not far beyond the sweep: the coarse liver's faces are ~1 cm2 against a 2 cm2 sweep,
  // so whole faces along the conformed borders open up to 1.4 x (140 % measured).
  EXPECT_LE(b.opened, 1.5 * b.swept) << what;
}

TEST(SimulationEdgeContact, BellyCutWithTheTipOutsideOpensTheThigh) {
  belly_cut_opens_the_swept_area(thigh(), 0.9, "thigh");  // 118 % measured
}
TEST(SimulationEdgeContact, BellyCutWithTheTipOutsideOpensTheLiver) {
  belly_cut_opens_the_swept_area(liver(), 0.9, "liver");  // 139 % measured
}

TEST(SimulationEdgeContact, LiftingOutOrSlidingInItsOwnIncisionStopsCuttingAFreshPressCutsAgain) {
  TestScene t = thigh();
  t.scene.scalpel.cut_pressure = 0.1;
  Simulation sim(t.scene);
  auto run = [&](const std::vector<BladePose>& path) {
    int cut_steps = 0;
    for (const BladePose& p : path) {
      const StepStats st = sim.step(p);
      cut_steps += st.cutting;
    }
    return cut_steps;
  };
  std::vector<BladePose> press, draw, back, lift;
  for (int k = 0; k <= kLowering; ++k) press.push_back(laid(t.site, 0.6, 7e-3 - k * 1e-4, 0));
  for (int k = 1; k <= 20; ++k) draw.push_back(laid(t.site, 0.6, -4e-3, -1e-3 * k));
  // Back along its own incision, heel first, staying inside what it has cut.
  for (int k = 1; k <= 15; ++k) back.push_back(laid(t.site, 0.6, -4e-3, -0.02 + 1e-3 * k));
  for (int k = 1; k <= 24; ++k) lift.push_back(laid(t.site, 0.6, -4e-3 + 5e-4 * k, -0.005));
  EXPECT_GT(run(press) + run(draw), 5);
  EXPECT_FALSE(sim.blade_path().empty());  // still cutting
  // Back: the stroke ends once the blade retraces its incision, and its end is conformed
  // (the front where the blade stopped, a few dozen tets); then the slide cuts nothing.
  size_t k = 0;
  for (; k < back.size() && !sim.blade_path().empty(); ++k) run({back[k]});
  EXPECT_LE(k, 3u) << "the stroke should end within the first steps back";
  run({back[k++]});  // the step that conforms the stroke's end
  const int tets = sim.counts().tets;
  run(std::vector<BladePose>(back.begin() + static_cast<long>(k), back.end()));
  EXPECT_TRUE(sim.blade_path().empty()) << "sliding through its own incision still cuts";
  EXPECT_LE(sim.counts().tets - tets, 8);     // nothing more while it slides
  EXPECT_FALSE(sim.last_stats().in_contact);  // the incision walls are never held
  run(lift);
  EXPECT_TRUE(sim.blade_path().empty());
  EXPECT_EQ(sim.last_stats().contact_nodes.size(), 0u);
  // Fresh skin 0.3 rad round the thigh: pressing there yields and cuts again.
  const Vec3 radial(std::cos(0.3), std::sin(0.3), 0);
  const Site fresh{0.06 * radial + Vec3(0, 0, 0.048), radial, Vec3::UnitZ()};
  const int cuts = sim.counts().cuts;
  std::vector<BladePose> again;
  for (int k = 0; k <= kLowering; ++k) again.push_back(laid(fresh, 0.6, 7e-3 - k * 1e-4, 0));
  for (int k = 1; k <= 10; ++k) again.push_back(laid(fresh, 0.6, -4e-3, -1e-3 * k));
  EXPECT_GT(run(again), 3);
  EXPECT_GT(sim.counts().cuts, cuts);
}

TEST(SimulationEdgeContact, NoCutWhileCuttingIsDisabled) {
  for (const TestScene& t : {thigh(), liver()}) {
    const Belly b = belly_cut(t, false, t.scene.source.c_str());
    EXPECT_TRUE(b.pressed);
    EXPECT_GT(b.peak_force, kBellyCutPressure);  // it would have cut
    EXPECT_EQ(b.cut_steps, 0);
    EXPECT_EQ(b.cuts, 0);
    EXPECT_EQ(b.opened, 0);
  }
}

TEST(SimulationEdgeContact, ForceDepthCurvesOfAFlatBladeAndATipPress) {
  // The thigh, pressed 5 mm past the first touch, cutting off: the flat blade presses a 2 cm
  // line, the tip one triangle. Continuous: no step adds more than a 0.1 mm deeper press
  // would at the deepest point.
  const TestScene t = thigh();
  const Press flat = press(t, 0.0, 7e-3), tip = press(t, -1, 7e-3);
  auto since_touch = [](const Press& p, double depth) {
    size_t first = 0;
    while (first < p.curve.size() && p.curve[first].second == 0) ++first;
    const size_t k = first + static_cast<size_t>(std::lround(depth / 5e-5));
    return k < p.curve.size() ? p.curve[k].second : -1.0;
  };
  std::printf("depth past first touch (mm) | flat blade |F| (N) | tip press |F| (N)\n");
  for (double d = 0; d <= 5e-3 + 1e-12; d += 5e-4)
    std::printf("%.1f | %.4f | %.4f\n", 1e3 * d, since_touch(flat, d), since_touch(tip, d));
  EXPECT_GT(since_touch(flat, 5e-3), since_touch(tip, 5e-3));  // a line presses more tissue
  EXPECT_GT(since_touch(tip, 5e-3), 0);
  for (const Press* p : {&flat, &tip}) {
    const size_t n = p->curve.size();
    const double per_tenth = p->curve[n - 1].second - p->curve[n - 3].second;  // 2 x 0.05 mm
    EXPECT_GT(per_tenth, 0);
    EXPECT_LE(p->max_jump, per_tenth * 1.0001);
  }
}

}  // namespace
}  // namespace stc
