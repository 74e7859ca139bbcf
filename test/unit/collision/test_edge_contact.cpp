// Edge contact (issue 14) on a 4 cm cube in 1 cm cells, without a solve: the "deformed"
// surface is the rest surface with every held node moved to where it is held (as an exact
// solve puts it) and every other node back at rest. A blade laid flat across the top face
// (z = 4 cm) and lowered must hold a band of nodes under its whole length, on its line,
// whether the line runs over triangle interiors, along mesh edges or through vertices; the
// band follows the blade when it slides; lifting it lets go.
#include "soft_tissue_cutting/collision/edge_contact.hpp"

#include "common/meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace stc {
namespace {

using test::cube_mesh;

constexpr double kTop = 0.04;

// A horizontal edge along `dir` (in the x-y plane) through `centre`, blade normal in the x-y
// plane, `length` long.
BladeEdge flat_edge(const Vec3& centre, const Vec3& dir, double length) {
  BladeEdge e;
  e.tip = centre - 0.5 * length * dir;
  e.heel = centre + 0.5 * length * dir;
  e.normal = Vec3::UnitZ().cross(dir).normalized();
  return e;
}

struct Stepper {
  TetMesh mesh = cube_mesh();
  SurfaceBvh bvh;
  EdgeContact contact;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
  std::optional<BladeEdge> previous;
  std::map<int, Vec3> held;
  Stepper() { bvh.build(mesh, {}, {}); }
  void step(const BladeEdge& edge) {
    held = contact.update(bvh, mesh, u, previous, edge);
    u.setZero();
    std::vector<Vec3> d(mesh.nodes.size(), Vec3::Zero());
    for (const auto& [node, ui] : held) d[node] = ui, u.segment<3>(3 * node) = ui;
    bvh.refit(mesh, d);
    previous = edge;
  }
};

// Distance from p to the (infinite) line of the edge.
double to_line(const BladeEdge& e, const Vec3& p) {
  const Vec3 d = (e.heel - e.tip).normalized();
  const Vec3 r = p - e.tip;
  return (r - r.dot(d) * d).norm();
}

void expect_band_under_the_blade(const Stepper& s, const BladeEdge& edge, const char* what) {
  ASSERT_FALSE(s.held.empty()) << what;
  const Vec3 d = (edge.heel - edge.tip).normalized();
  for (const auto& [node, ui] : s.held) {
    const Vec3 p = s.mesh.nodes[node] + ui;
    // On the blade line: at its depth exactly, sideways within the reach (0.6 x the longest
    // surface edge around the node, sqrt(2) cm here).
    EXPECT_NEAR(p.z(), edge.tip.z(), 1e-15) << what << " node " << node;
    EXPECT_LE(to_line(edge, p), 0.6 * std::sqrt(2.0) * 0.01 + 1e-15) << what;
    EXPECT_NEAR(s.mesh.nodes[node].z(), kTop, 1e-15) << what;  // only skin nodes
  }
  // No gap: every point of the edge over the top face has a held node within one cell.
  int samples = 0;
  for (double t = 0; t <= 1; t += 0.01) {
    const Vec3 p = edge.tip + t * (edge.heel - edge.tip);
    if (p.x() < 0.002 || p.x() > 0.038 || p.y() < 0.002 || p.y() > 0.038) continue;
    double nearest = 1;
    for (const auto& [node, ui] : s.held)
      nearest = std::min(nearest, (s.mesh.nodes[node] + ui - p).norm());
    EXPECT_LT(nearest, 0.01) << what << " at " << p.transpose();
    ++samples;
  }
  EXPECT_GT(samples, 20) << what;
  (void)d;
}

// Lower the blade from 1 mm above the top face to `depth` below it in 0.1 mm steps.
void lower(Stepper& s, const Vec3& centre, const Vec3& dir, double depth) {
  for (double z = kTop + 1e-3; z >= kTop - depth - 1e-12; z -= 1e-4)
    s.step(flat_edge(Vec3(centre.x(), centre.y(), z), dir, 0.06));
}

TEST(EdgeContact, FlatBladeHoldsABandUnderItsWholeLength) {
  // Over triangle interiors, along a row of vertices and mesh edges, and along the cells'
  // diagonals (the Kuhn split's face diagonals run along x = y).
  struct Case {
    const char* what;
    Vec3 centre, dir;
  } cases[] = {{"interiors", Vec3(0.02, 0.0153, 0), Vec3::UnitX()},
               {"vertex row", Vec3(0.02, 0.02, 0), Vec3::UnitX()},
               {"diagonal", Vec3(0.02, 0.02, 0), Vec3(1, 1, 0).normalized()},
               {"skew", Vec3(0.021, 0.019, 0), Vec3(1, 0.37, 0).normalized()}};
  for (const Case& c : cases) {
    Stepper s;
    lower(s, c.centre, c.dir, 1e-3);
    const BladeEdge edge = *s.previous;
    expect_band_under_the_blade(s, edge, c.what);
    // A band, not the whole face: at most the nodes within reach of the line.
    EXPECT_LE(s.held.size(), 20u) << c.what;
  }
}

TEST(EdgeContact, TheVertexRowIsHeldAndOnlyIt) {
  Stepper s;
  lower(s, Vec3(0.02, 0.02, 0), Vec3::UnitX(), 1e-3);
  // The line runs exactly over the top-face nodes y = 2 cm: all five are held, exactly on
  // the line; the neighbour rows (1 cm sideways) are beyond reach (0.6 x sqrt(2) cm).
  int row = 0;
  for (const auto& [node, ui] : s.held) {
    const Vec3 p = s.mesh.nodes[node] + ui;
    if (std::abs(s.mesh.nodes[node].y() - 0.02) < 1e-15) {
      ++row;
      EXPECT_NEAR(to_line(*s.previous, p), 0, 1e-15);
    }
  }
  EXPECT_EQ(row, 5);
  EXPECT_EQ(s.held.size(), 5u);
}

TEST(EdgeContact, TheIndentationFollowsTheBladeAndLiftingLetsGo) {
  Stepper s;
  const Vec3 centre(0.02, 0.0153, 0);
  lower(s, centre, Vec3::UnitX(), 1e-3);
  const double depth_z = s.previous->tip.z();
  // Slide sideways (along the blade normal) by 3 mm: the held nodes come along exactly.
  std::map<int, Vec3> before = s.held;
  for (int k = 1; k <= 30; ++k)
    s.step(flat_edge(Vec3(centre.x(), centre.y() + 1e-4 * k, depth_z), Vec3::UnitX(), 0.05));
  for (const auto& [node, ui] : before) {
    ASSERT_TRUE(s.held.count(node)) << node;
    EXPECT_NEAR((s.held[node] - ui - Vec3(0, 3e-3, 0)).norm(), 0, 1e-15);
  }
  // Slide along its length by 2 cm (a shorter blade, so it leaves nodes behind): nodes it
  // slid past are let go, nodes it reaches are taken, all on the line.
  Stepper t;
  const Vec3 start(0.012, 0.0153, 0);
  for (double z = kTop + 1e-3; z >= kTop - 1e-3 - 1e-12; z -= 1e-4)
    t.step(flat_edge(Vec3(start.x(), start.y(), z), Vec3::UnitX(), 0.015));
  const std::map<int, Vec3> first = t.held;
  for (int k = 1; k <= 40; ++k)
    t.step(flat_edge(Vec3(start.x() + 5e-4 * k, start.y(), kTop - 1e-3), Vec3::UnitX(), 0.015));
  const BladeEdge edge = *t.previous;
  ASSERT_FALSE(t.held.empty());
  for (const auto& [node, ui] : t.held) {
    const Vec3 p = t.mesh.nodes[node] + ui;
    EXPECT_NEAR(p.z(), kTop - 1e-3, 1e-15);
    EXPECT_GE(p.x(), edge.tip.x() - 1e-15);
    EXPECT_LE(p.x(), edge.heel.x() + 1e-15);
  }
  int kept = 0;
  for (const auto& [node, ui] : first) kept += t.held.count(node);
  EXPECT_LT(kept, static_cast<int>(first.size()));  // the band moved on
  bool reached_new = false;
  for (const auto& [node, ui] : t.held) reached_new |= !first.count(node);
  EXPECT_TRUE(reached_new);
  // Lift the blade back above the skin: everything is let go.
  for (double z = kTop - 1e-3; z <= kTop + 2e-4; z += 1e-4)
    t.step(flat_edge(Vec3(edge.tip.x() + 0.0075, start.y(), z), Vec3::UnitX(), 0.015));
  EXPECT_TRUE(t.held.empty());
  EXPECT_TRUE(t.contact.empty());
}

TEST(EdgeContact, ABladeBelowTheSkinFromTheStartCapturesNothing) {
  // Captures need the line to pass the node between two poses: a blade that appears deep
  // inside (e.g. after the tissue yielded and it cut its way in) holds nothing new.
  Stepper s;
  s.step(flat_edge(Vec3(0.02, 0.0153, kTop - 3e-3), Vec3::UnitX(), 0.03));
  s.step(flat_edge(Vec3(0.02, 0.0153, kTop - 3.1e-3), Vec3::UnitX(), 0.03));
  EXPECT_TRUE(s.held.empty());
}

TEST(EdgeContact, WrenchIsTheSumOfForcesAndMomentsAboutTheTip) {
  const Vec3 tip(0.01, 0.02, 0.03);
  const std::vector<Vec3> at = {Vec3(0.02, 0.02, 0.03), Vec3(0.03, 0.021, 0.029)};
  const std::vector<Vec3> holding = {Vec3(0, 0, -0.2), Vec3(0.01, 0, -0.3)};
  const BladeWrench w = blade_wrench(tip, at, holding);
  EXPECT_NEAR((w.force - Vec3(-0.01, 0, 0.5)).norm(), 0, 1e-15);
  const Vec3 torque = (at[0] - tip).cross(-holding[0]) + (at[1] - tip).cross(-holding[1]);
  EXPECT_NEAR((w.torque - torque).norm(), 0, 1e-16);
  // In the blade's frame: a blade whose edge runs along world +y, normal world -x.
  BladeEdge edge;
  edge.tip = tip;
  edge.heel = tip + Vec3(0, 0.02, 0);
  edge.normal = -Vec3::UnitX();
  const BladeWrench b = in_blade_frame(w, edge);
  EXPECT_NEAR(b.force.x(), w.force.y(), 1e-15);   // along the edge
  EXPECT_NEAR(b.force.y(), -w.force.x(), 1e-15);  // along the blade normal
  EXPECT_NEAR(b.force.z(), w.force.z(), 1e-15);   // x cross y = world z
  EXPECT_NEAR(b.torque.norm(), w.torque.norm(), 1e-16);
}

TEST(SegmentCrossing, ACollapsedTriangleIsNeverCrossed) {
  // Two vertices on the same point (contact held them on one blade point): e1 == e2, the
  // determinant is rounding noise; a crossing there would pull the triangle's fan in.
  const Vec3 a(0.01, 0.01, 0.04), p(0.013, 0.012, 0.04);
  double s;
  EXPECT_FALSE(
      segment_crosses_triangle(Vec3(0.0131, 0.0119, 0.037), Vec3(0.013, 0.012, 0.06), a, p, p, s));
  EXPECT_FALSE(
      segment_crosses_triangle(Vec3(0.0131, 0.0119, 0.037), Vec3(0.013, 0.012, 0.06), p, p, p, s));
}

// The early answer of swept_before_fraction (below: only whether the fraction reaches it) is
// the measured fraction's answer on every step of random strokes that go forward, turn back
// through their own sweeps and stop; where the fraction reaches it, the value is the measured
// one exactly.
TEST(SweptBefore, TheEarlyAnswerIsTheMeasuredOnes) {
  std::mt19937 rng(20261129);
  std::uniform_real_distribution<double> uniform(-1, 1);
  int retracing = 0, forward = 0;
  for (int stroke_index = 0; stroke_index < 40; ++stroke_index) {
    std::vector<BladeEdge> stroke;
    BladeEdge edge{Vec3(0, 0, 0), Vec3(0, 0.03, 0)};
    for (int k = 0; k < 60; ++k) {
      BladeEdge next;
      if (k % 20 < 12) {  // forward, wandering
        const Vec3 step =
            Vec3(1e-3, 0, 0) + 2e-4 * Vec3(uniform(rng), 0.2 * uniform(rng), uniform(rng));
        next = {edge.tip + step, edge.heel + step};
      } else if (k % 20 < 19) {  // back through its own incision, or a hair off it
        const BladeEdge& back =
            stroke[stroke.size() - 1 - static_cast<size_t>(2 * (k % 20 - 11) - 1)];
        const Vec3 hair =
            (k % 3 == 0 ? 3e-6 : 0.0) * Vec3(uniform(rng), uniform(rng), uniform(rng));
        next = {back.tip + hair, back.heel + hair};
      } else {
        next = edge;  // held still
      }
      if (!stroke.empty()) {
        const double measured = swept_before_fraction(stroke, edge, next);
        const double early = swept_before_fraction(stroke, edge, next, 1e-4, 0.9);
        ASSERT_EQ(measured >= 0.9, early >= 0.9) << "stroke " << stroke_index << " step " << k;
        if (measured >= 0.9) {
          EXPECT_EQ(early, measured);
        }
        (measured >= 0.9 ? retracing : forward) += 1;
      }
      stroke.push_back(edge);
      edge = next;
    }
  }
  EXPECT_GT(retracing, 100);  // both answers were asked for
  EXPECT_GT(forward, 1000);
  std::printf("swept before: %d steps retracing, %d not\n", retracing, forward);
}

}  // namespace
}  // namespace stc
