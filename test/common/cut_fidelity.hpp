// How faithfully a cut opens what the blade swept (rest coordinates): the figures issue-level
// acceptance is stated in, measured on any mesh.
//
//   swept area     area of the swept surface inside the measured region (the operation part
//                  less one element layer at the interface, which stays uncut by design)
//   opened area    area of open cut faces (boundary triangles marked cut) in that region, per
//                  side of the blade: a clean incision opens the swept area once on each side
//   Hausdorff      two-sided distance between the open cut faces and the swept surface, as a
//                  distance and as a multiple of the local tolerance max(0.5 mm, 0.25 h)
//   wall alignment area-weighted mean |n_face . n_blade| of the open cut faces (1 = the walls
//                  face exactly along the blade normal)
#pragma once

#include "soft_tissue_cutting/collision/tet_locator.hpp"
#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace stc {

// One planar piece of the swept surface and the blade normal it was swept with (unit).
struct SweptTriangle {
  std::array<Vec3, 3> x;
  Vec3 blade_normal = Vec3::UnitY();
};

// The measured region of an uncut rest mesh: operation tets none of whose nodes is an
// interface node. Kept as a copy of the uncut mesh, so it stays valid while the mesh is cut.
class MeasuredRegion {
 public:
  MeasuredRegion(const TetMesh& uncut, const std::vector<std::uint8_t>& operation_tet,
                 const std::vector<std::uint8_t>& interface_node);
  // Is p (rest) inside the region? local_edge: mean edge length of the uncut tet there.
  bool contains(const Vec3& p, double* local_edge = nullptr) const;
  // Mean edge length of the uncut tet containing p, anywhere in the mesh (0 outside).
  double edge_length_at(const Vec3& p) const;

 private:
  TetMesh mesh_;
  std::vector<std::uint8_t> inside_;
  std::vector<double> edge_length_;
  TetLocator locator_;
};

struct CutFidelity {
  double swept_area = 0;                  // m^2
  double covered_area = 0;                // m^2: swept area within tolerance of an open face
  std::array<double, 2> opened_area{};    // m^2: walls facing -n_blade, +n_blade
  double faces_to_sweep = 0;              // m: max distance, open cut faces -> swept surface
  double sweep_to_faces = 0;              // m: max distance, swept surface -> open cut faces
  double hausdorff = 0;                   // m: the larger of the two
  double hausdorff_over_tolerance = 0;    // max over samples of distance / tolerance
  double faces_over_tolerance = 0;        // the same, faces -> sweep only
  Vec3 worst_swept_point = Vec3::Zero();  // the swept point farthest from any open face
  Vec3 worst_face_point = Vec3::Zero();   // the open face point farthest (over tolerance)
                                          // from the swept surface
  double wall_alignment = 0;              // area-weighted mean |n_face . n_blade|
  int open_cut_faces = 0;                 // in the region
  // Per sweep triangle (same order): its swept area in the region and how much of that is
  // within tolerance of an open face (m^2; the sums are swept_area and covered_area).
  std::vector<double> swept_by_triangle, covered_by_triangle;
  // Per side (as opened_area): the swept area whose line along the blade normal meets an open
  // face of that side within the tolerance (m^2) - how much of the sweep each wall covers,
  // whatever the faces' own area (one face may be larger than the region, or lean across it).
  std::array<double, 2> walled_area{};
  // min(opened_area) / swept_area (0 when nothing was swept).
  double opening() const {
    return swept_area > 0 ? std::min(opened_area[0], opened_area[1]) / swept_area : 0;
  }
};

// sample_spacing: spacing of the samples on the swept surface (and so the resolution of the
// swept area and of the sweep -> faces distance).
CutFidelity measure_cut_fidelity(const MeasuredRegion& region, const TetMesh& cut_mesh,
                                 const std::vector<SweptTriangle>& sweep, double sample_spacing);

// Distance from p to triangle (a, b, c).
double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Writes, for a plot of where a cut's holes are (STC_FIDELITY_DUMP in the fidelity tests), one
// line per sweep triangle (S), open cut face (C, boundary triangles marked cut) and marked face
// (M), and with `tets` every tet (T: its four nodes, then their positions), each point in mm
// along `direction`, along `up` and along up x direction from `origin`. False if `path` cannot
// be written.
bool dump_cut(const char* path, const TetMesh& mesh, const std::vector<SweptTriangle>& sweep,
              const Vec3& origin, const Vec3& direction, const Vec3& up, bool tets);

}  // namespace stc
