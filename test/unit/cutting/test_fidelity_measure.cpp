// The cut-fidelity measure itself (test/common/cut_fidelity.hpp), on a cut whose faces are
// known exactly: a 4 cm cube of 1 cm cells severed along its node plane x = 2 cm. Swept
// surfaces placed on, beside and across that plane give figures that follow from geometry
// alone - what issue 9's matrix reports is then the cut, not the ruler.
#include "common/cut_fidelity.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace stc {
namespace {

constexpr double kSide = 0.04, kPlane = 0.02;
// The tolerance max(0.5 mm, 0.25 h), h the mean edge of a Kuhn tet of a 1 cm cell:
// (3 x 1 + 2 x sqrt(2) + sqrt(3)) cm / 6.
const double kTolerance = 0.25 * 0.01 * (3 + 2 * std::sqrt(2.0) + std::sqrt(3.0)) / 6;
constexpr double kSpacing = 0.25e-3;

struct SeveredCube {
  TetMesh uncut, mesh;
  std::unique_ptr<MeasuredRegion> region;
  SeveredCube() {
    GeneratorParams g;
    g.size = Vec3(kSide, kSide, kSide);
    g.cells = {4, 4, 4};
    uncut = make_box_mesh(g);
    mesh = uncut;
    CutState state = make_cut_state(mesh, {}, {});
    BladeEdge from, to;
    from.tip = Vec3(kPlane, -0.01, -0.01), from.heel = Vec3(kPlane, -0.01, kSide + 0.01);
    to.tip = Vec3(kPlane, kSide + 0.01, -0.01), to.heel = Vec3(kPlane, kSide + 0.01, kSide + 0.01);
    cut_sweep(mesh, state, from, to);
    region = std::make_unique<MeasuredRegion>(uncut, std::vector<std::uint8_t>{},
                                              std::vector<std::uint8_t>{});
  }
  // A square sweep of half-width `half` centred at (kPlane + offset, 2 cm, 2 cm), turned by
  // `tilt` about the y axis (its normal (cos tilt, 0, -sin tilt)).
  CutFidelity measure(double half, double offset, double tilt) const {
    const Vec3 centre(kPlane + offset, 0.5 * kSide, 0.5 * kSide);
    const Vec3 normal(std::cos(tilt), 0, -std::sin(tilt));
    const Vec3 across(std::sin(tilt), 0, std::cos(tilt)), along = Vec3::UnitY();
    const Vec3 a = centre - half * along - half * across, b = centre + half * along - half * across,
               c = centre + half * along + half * across, d = centre - half * along + half * across;
    std::vector<SweptTriangle> sweep = {{{a, b, c}, normal}, {{a, c, d}, normal}};
    return measure_cut_fidelity(*region, mesh, sweep, kSpacing);
  }
};

double walled(const CutFidelity& f, int side) { return f.walled_area[side] / f.swept_area; }

TEST(FidelityMeasure, ASweepOnTheCutIsWalledAndOpenedOnBothSides) {
  const SeveredCube cube;
  const CutFidelity f = cube.measure(0.5 * kSide, 0, 0);
  EXPECT_NEAR(f.swept_area, kSide * kSide, 1e-9);
  for (int side = 0; side < 2; ++side) {
    EXPECT_NEAR(f.opened_area[side], kSide * kSide, 1e-9) << side;
    EXPECT_NEAR(walled(f, side), 1.0, 1e-9) << side;
  }
  EXPECT_NEAR(f.hausdorff, 0, 1e-9);
  EXPECT_NEAR(f.wall_alignment, 1, 1e-9);
}

TEST(FidelityMeasure, ASweepBesideTheCutIsWalledOnlyWithinTheTolerance) {
  const SeveredCube cube;
  const CutFidelity near = cube.measure(0.01, 0.8 * kTolerance, 0);
  const CutFidelity far = cube.measure(0.01, 1.2 * kTolerance, 0);
  for (int side = 0; side < 2; ++side) {
    EXPECT_NEAR(walled(near, side), 1.0, 1e-9) << side;
    EXPECT_NEAR(walled(far, side), 0.0, 1e-9) << side;
  }
  EXPECT_NEAR(near.covered_area, near.swept_area, 1e-12);
  EXPECT_NEAR(far.covered_area, 0, 1e-12);
  // All the cut's faces count (the region is the whole cube), however little of them the
  // small sweep spans.
  EXPECT_NEAR(far.opened_area[0], kSide * kSide, 1e-9);
}

TEST(FidelityMeasure, ASweepAcrossTheCutIsWalledWhereItsNormalMeetsTheCutInTolerance) {
  // Tilted by 60 deg about the line where it crosses the cut plane: from a point at distance
  // d (across) from that line, the line along the normal meets the plane d tan(60 deg) away.
  // Walled: |d| <= tolerance / tan(60 deg), a band of that half-width across the 2 cm square.
  const SeveredCube cube;
  const double half = 0.01, tilt = M_PI / 3;
  const CutFidelity f = cube.measure(half, 0, tilt);
  const double expected = kTolerance / std::tan(tilt) / half;
  for (int side = 0; side < 2; ++side)
    EXPECT_NEAR(walled(f, side), expected, 0.03) << side << ": expected " << expected;
  // Within the tolerance of a face in any direction ("covered", what the Hausdorff distance
  // sees): |d| sin(60 deg) <= tolerance, a band twice as wide (1 / cos(60 deg)).
  EXPECT_NEAR(f.covered_area / f.swept_area, 2 * expected, 0.03);
}

}  // namespace
}  // namespace stc
