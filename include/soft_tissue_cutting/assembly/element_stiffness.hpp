// Linear tetrahedron stiffness (docs/DESIGN.md section 2): K_e = V B^T D B, 12 x 12.
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <Eigen/Core>

namespace stc {

using Mat12 = Eigen::Matrix<double, 12, 12>;
using StrainDisplacement = Eigen::Matrix<double, 6, 12>;  // B
using Elasticity = Eigen::Matrix<double, 6, 6>;           // D

struct LameParameters {
  double lambda = 0;  // E nu / ((1+nu)(1-2nu))
  double mu = 0;      // E / (2(1+nu))
};
LameParameters lame_parameters(double young_modulus, double poisson_ratio);

// Isotropic D for strains ordered (xx, yy, zz, xy, yz, zx) with engineering shear
// (gamma = 2 eps), so the shear diagonal is mu.
Elasticity isotropic_elasticity(double young_modulus, double poisson_ratio);

// B: eps = B u_e with u_e = (u0x, u0y, u0z, u1x, ..., u3z). Constant over the tet because the
// shape functions are linear; their gradients are the rows of [x1-x0, x2-x0, x3-x0]^-1
// (grad N0 = -(sum of the others)).
StrainDisplacement strain_displacement(const Vec3& x0, const Vec3& x1, const Vec3& x2,
                                       const Vec3& x3);

// K_e = V B^T D B with V the (positive) volume. Throws std::invalid_argument for a
// degenerate (zero-volume) tet.
Mat12 element_stiffness(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                        double young_modulus, double poisson_ratio);

}  // namespace stc
