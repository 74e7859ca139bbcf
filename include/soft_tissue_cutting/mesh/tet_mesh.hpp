// The linear tetrahedral mesh every pipeline stage works on (docs/DESIGN.md section 2).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace stc {

using Vec3 = Eigen::Vector3d;
using Tet = std::array<int, 4>;
using Tri = std::array<int, 3>;

// Local face f of a tet is the face opposite its vertex f. For a positively oriented tet
// (det[x1-x0, x2-x0, x3-x0] > 0) these vertex orders give outward normals (right-hand rule).
inline constexpr std::array<std::array<int, 3>, 4> kTetFaces = {
    {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

struct TetMesh {
  std::vector<Vec3> nodes;  // rest (undeformed) positions, m
  std::vector<Tet> tets;    // node indices, positively oriented
  // Bit f set: local face f of the tet lies on a cut (drawn as tissue interior). Empty or
  // tets.size() long.
  std::vector<std::uint8_t> cut_faces;

  int num_nodes() const { return static_cast<int>(nodes.size()); }
  int num_tets() const { return static_cast<int>(tets.size()); }
  bool is_cut_face(int tet, int face) const {
    return !cut_faces.empty() && (cut_faces[tet] >> face) & 1u;
  }
};

// Signed volume of a tet: det[x1-x0, x2-x0, x3-x0] / 6.
double signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);
double tet_volume(const TetMesh& mesh, int tet);
double total_volume(const TetMesh& mesh);
// FNV-1a over the topology and the rest positions' bits (not cut_faces), 16 hex digits:
// equal meshes, equal hashes (replays must agree).
std::string mesh_hash(const TetMesh& mesh);

// A connected piece of a tet mesh (cutting/free_pieces.hpp, mesh/face_adjacency.hpp).
struct MeshPiece {
  std::vector<int> tets;   // ascending
  std::vector<int> nodes;  // ascending
};

}  // namespace stc
