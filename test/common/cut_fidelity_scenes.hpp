// Meshes and blade strokes for measuring cut fidelity (issue 9): the thigh and TetGen livers
// made at test time from the SOFA livers in config/meshes (sofa_liver2.obj, and the boundary of
// sofa_liver.msh re-meshed), scaled to 15 cm; strokes of a vertical or tilted blade along a
// straight or curved path at a fixed depth under the rest surface, in steps of any size.
#pragma once

#include "common/cut_fidelity.hpp"
#include "cutting/cut_state.hpp"
#include "cutting/cut_sweep.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/collision/surface_bvh.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"
#include "soft_tissue_cutting/partition/partition.hpp"
#include "soft_tissue_cutting/scene/scene.hpp"

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace stc::fidelity {

// A TetGen liver, largest extent `extent` metres. source: "liver2" (sofa_liver2.obj) or
// "liver" (the boundary of sofa_liver.msh). tets: about how many (TetGen's a switch, q1.4).
inline TetMesh tetgen_liver(const std::string& source, int tets, double extent = 0.15) {
  static std::map<std::pair<std::string, int>, TetMesh> cache;
  const auto key = std::make_pair(source, tets);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  const std::string dir = TISSUE_SHARED_MESH_DIR;
  std::string surface_file = dir + "/sofa_liver2.obj";
  double volume = 0;
  if (source == "liver") {
    // sofa_liver.msh's boundary as an OBJ, so it is re-meshed by the same TetGen path.
    const TetMesh coarse = read_mesh(dir + "/sofa_liver.msh");
    volume = total_volume(coarse);
    surface_file = "/tmp/stc_liver_boundary_" + std::to_string(getpid()) + ".obj";
    std::ofstream obj(surface_file);
    for (const Vec3& x : coarse.nodes) obj << "v " << x.x() << ' ' << x.y() << ' ' << x.z() << '\n';
    for (const BoundaryTriangle& t : extract_boundary_surface(coarse).triangles)
      obj << "f " << t.nodes[0] + 1 << ' ' << t.nodes[1] + 1 << ' ' << t.nodes[2] + 1 << '\n';
  }
  // sofa_liver2.obj's surface is already fine (1170 vertices): its coarse mesh keeps the
  // surface (Y) with a looser radius-edge bound (MESHES.md: ~7k tets), its fine one is plain
  // q1.4 (~46k). The coarse liver's boundary gets a volume bound (q1.4 adds about as many
  // tets again as the bound asks for, hence the factor).
  char switches[64];
  if (source == "liver")
    std::snprintf(switches, sizeof switches, "pq1.4a%.6gQ", 6.4 * volume / tets);
  else
    std::snprintf(switches, sizeof switches, "%s", tets < 20000 ? "pYq1.4/10Q" : "pq1.4Q");
  TetMesh mesh = read_mesh(surface_file, MeshReadOptions{switches});
  if (source == "liver") std::remove(surface_file.c_str());
  Vec3 lo = mesh.nodes[0], hi = lo;
  for (const Vec3& x : mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const double s = extent / (hi - lo).maxCoeff();
  for (Vec3& x : mesh.nodes) x = (x - lo) * s;  // min corner at the origin
  cache[key] = mesh;
  return mesh;
}

// The highest node (largest y): where the liver's operation sphere is centred.
inline Vec3 top_node(const TetMesh& mesh) {
  Vec3 top = mesh.nodes[0];
  for (const Vec3& x : mesh.nodes)
    if (x.y() > top.y()) top = x;
  return top;
}

// Where the line p + s up (from far "above") first meets the surface, or nothing.
inline std::optional<Vec3> surface_above(const std::vector<Vec3>& x, const BoundarySurface& surface,
                                         const Vec3& p, const Vec3& up) {
  const Vec3 from = p + 1.0 * up, to = p - 1.0 * up;
  double best = 2;
  for (const BoundaryTriangle& t : surface.triangles) {
    double s = 0;
    if (segment_crosses_triangle(from, to, x[t.nodes[0]], x[t.nodes[1]], x[t.nodes[2]], s) &&
        s < best)
      best = s;
  }
  if (best > 1) return std::nullopt;
  return from + best * (to - from);
}

struct Stroke {
  Vec3 centre;     // middle of the path, on the surface's horizontal
  Vec3 up;         // out of the tissue: a vertical blade's edge points this way
  Vec3 direction;  // of travel at the centre, perpendicular to up
  double length = 0.03;
  double depth = 0.01;  // tip below the surface along -up
  double tilt_deg = 0;  // edge tilted from up towards the blade normal
  double radius = 0;    // 0: straight; else a circular arc of this radius
  double step = 1e-3;   // distance between poses
};

// The stroke's poses: tip `depth` under the surface of `x` (node positions: rest or deformed).
inline std::vector<BladePose> stroke_poses(const Stroke& s, const std::vector<Vec3>& x,
                                           const BoundarySurface& surface) {
  const Vec3 side = s.up.cross(s.direction).normalized();
  const int steps = std::max(1, static_cast<int>(std::lround(s.length / s.step)));
  std::vector<BladePose> poses;
  for (int i = 0; i <= steps; ++i) {
    const double a = -0.5 * s.length + s.length * i / steps;
    Vec3 p = s.centre + a * s.direction, t = s.direction;
    if (s.radius > 0) {
      const double phi = a / s.radius;
      p = s.centre + s.radius * std::sin(phi) * s.direction + s.radius * (1 - std::cos(phi)) * side;
      t = std::cos(phi) * s.direction + std::sin(phi) * side;
    }
    const auto top = surface_above(x, surface, p, s.up);
    if (!top) continue;
    const double tilt = s.tilt_deg * M_PI / 180;
    const Vec3 normal0 = s.up.cross(t).normalized();
    const Vec3 edge = std::cos(tilt) * s.up + std::sin(tilt) * normal0;
    const Vec3 normal = edge.cross(t).normalized();
    Eigen::Matrix3d r;
    r.col(0) = edge;
    r.col(1) = normal;
    r.col(2) = edge.cross(normal);
    BladePose pose;
    pose.position = *top - s.depth * s.up;
    pose.orientation = Eigen::Quaterniond(r);
    poses.push_back(pose);
  }
  return poses;
}

// The two planar triangles cut_sweep inserts for one step (tip, heel order as it does).
inline void add_sweep(const BladeEdge& a, const BladeEdge& b, std::vector<SweptTriangle>& out) {
  out.push_back({{a.tip, a.heel, b.heel}, a.normal});
  out.push_back({{a.tip, b.heel, b.tip}, a.normal});
}

// The TetGen liver (sofa_liver2.obj, ~7k tets, 15 cm) on its fixed underside (lowest 15 %)
// under gravity, E = 3 kPa: its top sags by centimetres. Operation sphere of 4 cm at the top.
inline Scene sagging_liver() {
  Scene s;
  s.source = "tetgen liver2 (test)";
  s.mesh = tetgen_liver("liver2", 5000);
  s.material = Material{3000.0, 0.45, 1000.0};
  s.gravity = Vec3(0, -9.81, 0);
  Vec3 lo = s.mesh.nodes[0], hi = lo;
  for (const Vec3& x : s.mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  NodeSelector underside;
  underside.kind = NodeSelector::Kind::kBox;
  underside.box =
      Box{lo - Vec3::Constant(1), Vec3(hi.x() + 1, lo.y() + 0.15 * (hi.y() - lo.y()), hi.z() + 1)};
  s.fixed.push_back(underside);
  s.operation_region.kind = OperationRegion::Kind::kSphere;
  s.operation_region.sphere = Sphere{top_node(s.mesh), 0.04};
  s.scalpel = ScalpelParams{0.02, 0.5};
  s.solver = SolverParams{Backend::kCpu, 1e-10, 4000};
  return s;
}

// `strokes` 2.4 cm strokes in 3 mm sweeps across the top of a liver from
// tetgen_liver, each along another direction and tilt, each ended (finish_stroke): cuts that
// bisect tets, move nodes onto the cut and, from the second stroke on, smooth and flip the
// last one's tets. Returns the results' totals (moved nodes listed, counts summed).
inline CutResult crossing_strokes(TetMesh& mesh, CutState& state, int strokes,
                                  const CutOptions& options = {}) {
  CutResult total;
  const Vec3 top = top_node(mesh);
  for (int k = 0; k < strokes; ++k) {
    const Vec3 tip = top + Vec3(-0.03 + 0.011 * k, -0.012 - 0.002 * k, -0.02 + 0.007 * k);
    const Vec3 along = Vec3(1, 0.15 * (k % 3), 0.5 - 0.2 * k).normalized();
    BladeEdge from{tip, tip + 0.04 * Vec3(0.3 - 0.1 * k, 1, 0.2 * k).normalized(), Vec3::UnitZ()};
    for (int step = 0; step < 8; ++step) {
      BladeEdge to = from;
      to.tip += 0.003 * along;
      to.heel += 0.003 * along;
      const CutResult r = cut_sweep(mesh, state, from, to, options);
      total.moved_nodes.insert(total.moved_nodes.end(), r.moved_nodes.begin(), r.moved_nodes.end());
      total.flips += r.flips;
      total.tets_split += r.tets_split;
      from = to;
    }
    finish_stroke(mesh, state, options);
  }
  return total;
}

}  // namespace stc::fidelity
