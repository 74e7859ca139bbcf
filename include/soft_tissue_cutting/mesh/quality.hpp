// Element quality measures used to judge generated and cut meshes.
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

namespace stc {

// The six dihedral angles of a tet, in degrees.
std::array<double, 6> dihedral_angles_deg(const Vec3& a, const Vec3& b, const Vec3& c,
                                          const Vec3& d);

// The smallest of them: the same value as the least of dihedral_angles_deg, with one acos
// instead of six (a node move's quality test evaluates it for every tet of a star, many times).
double smallest_dihedral_deg(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

// 6 sqrt(2) signed volume / (longest edge)^3: 1 for a regular tet, 0 for a flat one, negative
// for an inverted one (0 when all corners coincide).
double volume_ratio(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

struct MeshQuality {
  double min_dihedral_deg = 0;
  double max_dihedral_deg = 0;
  double min_volume = 0;
  double max_volume = 0;
  // Smallest volume / (longest edge)^3 * 6 sqrt(2): 1 for a regular tet, 0 for a flat one.
  double min_volume_ratio = 0;
};

MeshQuality mesh_quality(const TetMesh& mesh);

}  // namespace stc
