// mesh/quality.hpp: the dihedral angles of a tet, and the smallest of them taken with one acos.
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace stc {
namespace {

TEST(MeshQuality, RegularTetHasEqualAngles) {
  const Vec3 a(1, 1, 1), b(1, -1, -1), c(-1, 1, -1), d(-1, -1, 1);
  for (double angle : dihedral_angles_deg(a, b, c, d))
    EXPECT_NEAR(angle, std::acos(1.0 / 3.0) * 180.0 / M_PI, 1e-12);  // 70.53 deg
  EXPECT_NEAR(smallest_dihedral_deg(a, b, c, d), 70.528779365509308, 1e-12);
}

TEST(MeshQuality, SmallestDihedralIsTheLeastOfTheSixBitForBit) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < 10000; ++k) {
    Vec3 p[4];
    for (Vec3& x : p) x = Vec3(unit(rng), unit(rng), unit(rng));
    if (k % 3 == 0) p[3] = (p[0] + p[1] + p[2]) / 3 + 1e-4 * p[3];  // slivers and caps too
    const auto angles = dihedral_angles_deg(p[0], p[1], p[2], p[3]);
    ASSERT_EQ(smallest_dihedral_deg(p[0], p[1], p[2], p[3]),
              *std::min_element(angles.begin(), angles.end()))
        << "tet " << k;
  }
}

}  // namespace
}  // namespace stc
