#include "soft_tissue_cutting/assembly/element_stiffness.hpp"

#include <Eigen/LU>

#include <stdexcept>

namespace stc {

LameParameters lame_parameters(double e, double nu) {
  return {e * nu / ((1 + nu) * (1 - 2 * nu)), e / (2 * (1 + nu))};
}

Elasticity isotropic_elasticity(double e, double nu) {
  const LameParameters l = lame_parameters(e, nu);
  Elasticity d = Elasticity::Zero();
  d.topLeftCorner<3, 3>().setConstant(l.lambda);
  d.topLeftCorner<3, 3>().diagonal().array() += 2 * l.mu;
  d.bottomRightCorner<3, 3>().diagonal().setConstant(l.mu);  // engineering shear
  return d;
}

StrainDisplacement strain_displacement(const Vec3& x0, const Vec3& x1, const Vec3& x2,
                                       const Vec3& x3) {
  Eigen::Matrix3d j;
  j.col(0) = x1 - x0;
  j.col(1) = x2 - x0;
  j.col(2) = x3 - x0;
  // N_i(x) = (J^-1 (x - x0))_i for i = 1..3, N_0 = 1 - N_1 - N_2 - N_3.
  const Eigen::Matrix3d jinv = j.inverse();
  Eigen::Matrix<double, 3, 4> g;  // column a = grad N_a
  g.rightCols<3>() = jinv.transpose();
  g.col(0) = -g.rightCols<3>().rowwise().sum();
  StrainDisplacement b = StrainDisplacement::Zero();
  for (int a = 0; a < 4; ++a) {
    const double gx = g(0, a), gy = g(1, a), gz = g(2, a);
    const int c = 3 * a;
    b(0, c) = gx;                        // eps_xx
    b(1, c + 1) = gy;                    // eps_yy
    b(2, c + 2) = gz;                    // eps_zz
    b(3, c) = gy, b(3, c + 1) = gx;      // gamma_xy
    b(4, c + 1) = gz, b(4, c + 2) = gy;  // gamma_yz
    b(5, c) = gz, b(5, c + 2) = gx;      // gamma_zx
  }
  return b;
}

Mat12 element_stiffness(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3, double e,
                        double nu) {
  const double v = signed_volume(x0, x1, x2, x3);
  if (!(v > 0)) throw std::invalid_argument("element_stiffness: tet with non-positive volume");
  const StrainDisplacement b = strain_displacement(x0, x1, x2, x3);
  Mat12 k = v * (b.transpose() * isotropic_elasticity(e, nu) * b);
  return 0.5 * (k + k.transpose());  // exact symmetry regardless of rounding
}

}  // namespace stc
