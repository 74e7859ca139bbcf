#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {

namespace {

// Outward unit face normals (face f opposite vertex f). The dihedral angle at the edge shared by
// faces f and g is pi minus the angle between their outward normals.
std::array<Vec3, 4> outward_unit_normals(const Vec3& a, const Vec3& b, const Vec3& c,
                                         const Vec3& d) {
  const Vec3 p[4] = {a, b, c, d};
  std::array<Vec3, 4> n;
  for (int f = 0; f < 4; ++f) {
    const auto& lf = kTetFaces[f];
    n[f] = (p[lf[1]] - p[lf[0]]).cross(p[lf[2]] - p[lf[0]]);
    const double len = n[f].norm();
    if (len > 0) n[f] /= len;
  }
  return n;
}

double angle_deg(double normals_dot) {
  return 180.0 - std::acos(std::clamp(normals_dot, -1.0, 1.0)) * 180.0 / M_PI;
}

}  // namespace

std::array<double, 6> dihedral_angles_deg(const Vec3& a, const Vec3& b, const Vec3& c,
                                          const Vec3& d) {
  const std::array<Vec3, 4> n = outward_unit_normals(a, b, c, d);
  std::array<double, 6> angles{};
  int k = 0;
  for (int f = 0; f < 4; ++f)
    for (int g = f + 1; g < 4; ++g) angles[k++] = angle_deg(n[f].dot(n[g]));
  return angles;
}

double smallest_dihedral_deg(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  // The angle grows as the normals' dot product falls, and every step of angle_deg is
  // monotonic: the least dot product gives the smallest angle, bit for bit.
  const std::array<Vec3, 4> n = outward_unit_normals(a, b, c, d);
  double least = 1e300;
  for (int f = 0; f < 4; ++f)
    for (int g = f + 1; g < 4; ++g) least = std::min(least, n[f].dot(n[g]));
  return angle_deg(least);
}

double volume_ratio(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3* p[4] = {&a, &b, &c, &d};
  double longest = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) longest = std::max(longest, (*p[i] - *p[j]).norm());
  // A regular tet with edge L has volume L^3 / (6 sqrt 2).
  return longest > 0
             ? 6 * std::sqrt(2.0) * signed_volume(a, b, c, d) / (longest * longest * longest)
             : 0;
}

MeshQuality mesh_quality(const TetMesh& mesh) {
  MeshQuality q;
  q.min_dihedral_deg = q.min_volume = q.min_volume_ratio = std::numeric_limits<double>::max();
  q.max_dihedral_deg = q.max_volume = -std::numeric_limits<double>::max();
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const Tet& tet = mesh.tets[t];
    const Vec3 &a = mesh.nodes[tet[0]], &b = mesh.nodes[tet[1]], &c = mesh.nodes[tet[2]],
               &d = mesh.nodes[tet[3]];
    for (double angle : dihedral_angles_deg(a, b, c, d)) {
      q.min_dihedral_deg = std::min(q.min_dihedral_deg, angle);
      q.max_dihedral_deg = std::max(q.max_dihedral_deg, angle);
    }
    const double v = signed_volume(a, b, c, d);
    q.min_volume = std::min(q.min_volume, v);
    q.max_volume = std::max(q.max_volume, v);
    q.min_volume_ratio = std::min(q.min_volume_ratio, volume_ratio(a, b, c, d));
  }
  if (mesh.tets.empty()) q = MeshQuality{};
  return q;
}

}  // namespace stc
