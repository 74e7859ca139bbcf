#include "common/cut_fidelity.hpp"

#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace stc {
namespace {

constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

double tolerance_at(double local_edge) { return std::max(0.5e-3, 0.25 * local_edge); }

// Samples of triangle (a, b, c) with spacing about h: centroids of an n x n subdivision, each
// standing for area / n^2.
void sample_triangle(const std::array<Vec3, 3>& x, double h, std::vector<Vec3>& points,
                     double& weight) {
  const double longest =
      std::max({(x[1] - x[0]).norm(), (x[2] - x[1]).norm(), (x[0] - x[2]).norm()});
  const int n = std::clamp(static_cast<int>(std::ceil(longest / h)), 1, 400);
  weight = 0.5 * (x[1] - x[0]).cross(x[2] - x[0]).norm() / (n * n);
  points.clear();
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      // upward sub-triangle (i, j), (i+1, j), (i, j+1)
      points.push_back(x[0] + ((i + 1.0 / 3) * (x[1] - x[0]) + (j + 1.0 / 3) * (x[2] - x[0])) / n);
      if (i + j + 1 < n)  // downward one (i+1, j), (i, j+1), (i+1, j+1)
        points.push_back(x[0] +
                         ((i + 2.0 / 3) * (x[1] - x[0]) + (j + 2.0 / 3) * (x[2] - x[0])) / n);
    }
}

}  // namespace

double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  if (area2 > 0) {
    const Vec3 q = p - n * (n.dot(p - a) / area2);
    const double u = n.dot((b - q).cross(c - q)), v = n.dot((c - q).cross(a - q));
    if (u >= 0 && v >= 0 && area2 - u - v >= 0) return (p - q).norm();
  }
  return std::min({(p - closest_point_on_segment(a, b, p)).norm(),
                   (p - closest_point_on_segment(b, c, p)).norm(),
                   (p - closest_point_on_segment(c, a, p)).norm()});
}

MeasuredRegion::MeasuredRegion(const TetMesh& uncut, const std::vector<std::uint8_t>& operation_tet,
                               const std::vector<std::uint8_t>& interface_node)
    : mesh_(uncut) {
  inside_.assign(mesh_.tets.size(), 0);
  edge_length_.assign(mesh_.tets.size(), 0);
  for (int t = 0; t < mesh_.num_tets(); ++t) {
    const Tet& k = mesh_.tets[t];
    bool in = operation_tet.empty() || operation_tet[t];
    for (int v : k) in = in && (interface_node.empty() || !interface_node[v]);
    inside_[t] = in;
    double sum = 0;
    for (const auto& e : kEdges) sum += (mesh_.nodes[k[e[0]]] - mesh_.nodes[k[e[1]]]).norm();
    edge_length_[t] = sum / 6;
  }
  locator_.build(mesh_, mesh_.nodes);
}

bool MeasuredRegion::contains(const Vec3& p, double* local_edge) const {
  const auto hit = locator_.locate(p);
  if (!hit || !inside_[hit->tet]) return false;
  if (local_edge) *local_edge = edge_length_[hit->tet];
  return true;
}

double MeasuredRegion::edge_length_at(const Vec3& p) const {
  const auto hit = locator_.locate(p);
  return hit ? edge_length_[hit->tet] : 0.0;
}

CutFidelity measure_cut_fidelity(const MeasuredRegion& region, const TetMesh& mesh,
                                 const std::vector<SweptTriangle>& sweep, double spacing) {
  CutFidelity out;
  // Open cut faces (all of them: a swept point may be opened by a face just outside the
  // region) and their outward normals.
  struct Face {
    std::array<Vec3, 3> x;
    Vec3 normal;
    double area;
  };
  std::vector<Face> faces;
  for (const BoundaryTriangle& t : extract_boundary_surface(mesh).triangles) {
    if (!t.cut) continue;
    Face f{
        {mesh.nodes[t.nodes[0]], mesh.nodes[t.nodes[1]], mesh.nodes[t.nodes[2]]}, Vec3::Zero(), 0};
    const Vec3 n = (f.x[1] - f.x[0]).cross(f.x[2] - f.x[0]);
    f.area = 0.5 * n.norm();
    if (!(f.area > 0)) continue;
    f.normal = n.normalized();
    faces.push_back(f);
  }
  std::vector<Vec3> sweep_normal;
  for (const SweptTriangle& s : sweep) {
    Vec3 n = (s.x[1] - s.x[0]).cross(s.x[2] - s.x[0]);
    n = n.norm() > 0 ? n.normalized() : s.blade_normal;
    sweep_normal.push_back(n.dot(s.blade_normal) < 0 ? -n : n);
  }
  auto nearest_sweep = [&](const Vec3& p, int* which) {
    double best = INFINITY;
    for (size_t k = 0; k < sweep.size(); ++k) {
      const double d = point_triangle_distance(p, sweep[k].x[0], sweep[k].x[1], sweep[k].x[2]);
      if (d < best) best = d, *which = static_cast<int>(k);
    }
    return best;
  };

  // Faces -> sweep, opened area per side, wall alignment.
  double aligned = 0, counted = 0;
  for (const Face& f : faces) {
    const Vec3 centroid = (f.x[0] + f.x[1] + f.x[2]) / 3;
    double h = 0;
    if (!region.contains(centroid, &h)) continue;
    ++out.open_cut_faces;
    int which = -1;
    const std::array<Vec3, 7> points = {f.x[0],
                                        f.x[1],
                                        f.x[2],
                                        centroid,
                                        0.5 * (f.x[0] + f.x[1]),
                                        0.5 * (f.x[1] + f.x[2]),
                                        0.5 * (f.x[2] + f.x[0])};
    for (const Vec3& p : points) {
      int k = -1;
      const double d = nearest_sweep(p, &k);
      if (which < 0 || &p == &points[3]) which = k;
      out.faces_to_sweep = std::max(out.faces_to_sweep, d);
      if (d / tolerance_at(h) > out.faces_over_tolerance)
        out.faces_over_tolerance = d / tolerance_at(h), out.worst_face_point = p;
    }
    if (which < 0) continue;
    const double c = f.normal.dot(sweep_normal[static_cast<size_t>(which)]);
    out.opened_area[c > 0 ? 1 : 0] += f.area;
    aligned += std::abs(c) * f.area;
    counted += f.area;
  }
  out.wall_alignment = counted > 0 ? aligned / counted : 0;

  // Sweep -> faces, swept area.
  AabbTree face_tree;
  {
    std::vector<Box3> boxes;
    for (const Face& f : faces) {
      Box3 b(f.x[0], f.x[0]);
      b.extend(f.x[1]);
      b.extend(f.x[2]);
      boxes.push_back(b);
    }
    face_tree.build(boxes);
  }
  std::vector<Vec3> points;
  out.swept_by_triangle.assign(sweep.size(), 0.0);
  out.covered_by_triangle.assign(sweep.size(), 0.0);
  for (size_t k = 0; k < sweep.size(); ++k) {
    double weight = 0;
    sample_triangle(sweep[k].x, spacing, points, weight);
    for (const Vec3& p : points) {
      double h = 0;
      if (!region.contains(p, &h)) continue;
      out.swept_area += weight;
      out.swept_by_triangle[k] += weight;
      // Nearest face: search growing boxes around p until one holds a face that is nearer
      // than the box's half-width (then no face outside it can be nearer).
      double best = INFINITY;
      for (double r = tolerance_at(h); r < 2.0 && !(best <= r); r *= 4) {
        std::vector<int> near;
        face_tree.overlapping(Box3(p - Vec3::Constant(r), p + Vec3::Constant(r)), near);
        for (int k : near) {
          const Face& f = faces[static_cast<size_t>(k)];
          best = std::min(best, point_triangle_distance(p, f.x[0], f.x[1], f.x[2]));
        }
      }
      if (!std::isfinite(best)) best = 2.0;  // nothing opened near: 2 m stands for "no face"
      if (best <= tolerance_at(h)) out.covered_area += weight, out.covered_by_triangle[k] += weight;
      // Walled: the line through p along the blade normal meets an open face of each side
      // within the tolerance (faces within it of p are among those searched above).
      std::vector<int> near;
      const double reach = tolerance_at(h);
      face_tree.overlapping(Box3(p - Vec3::Constant(reach), p + Vec3::Constant(reach)), near);
      std::array<bool, 2> walled{};
      for (int j : near) {
        const Face& f = faces[static_cast<size_t>(j)];
        const double c = f.normal.dot(sweep_normal[k]);
        if (std::abs(c) < 1e-6 || walled[c > 0 ? 1 : 0]) continue;
        const double along = f.normal.dot(f.x[0] - p) / c;  // p + along n lies on f's plane
        if (std::abs(along) > reach) continue;
        const Vec3 q = p + along * sweep_normal[k];
        const Vec3 n = (f.x[1] - f.x[0]).cross(f.x[2] - f.x[0]);
        const double u = n.dot((f.x[1] - q).cross(f.x[2] - q)),
                     v = n.dot((f.x[2] - q).cross(f.x[0] - q));
        if (u >= 0 && v >= 0 && n.squaredNorm() - u - v >= 0) walled[c > 0 ? 1 : 0] = true;
      }
      for (int side = 0; side < 2; ++side) out.walled_area[side] += walled[side] ? weight : 0.0;
      if (best > out.sweep_to_faces) out.sweep_to_faces = best, out.worst_swept_point = p;
      out.hausdorff_over_tolerance = std::max(out.hausdorff_over_tolerance, best / tolerance_at(h));
    }
  }
  out.hausdorff = std::max(out.faces_to_sweep, out.sweep_to_faces);
  out.hausdorff_over_tolerance = std::max(out.hausdorff_over_tolerance, out.faces_over_tolerance);
  return out;
}

bool dump_cut(const char* path, const TetMesh& mesh, const std::vector<SweptTriangle>& sweep,
              const Vec3& origin, const Vec3& direction, const Vec3& up, bool tets) {
  FILE* f = std::fopen(path, "w");
  if (f == nullptr) return false;
  const Vec3 aside = up.cross(direction);
  auto point = [&](const Vec3& x) {
    const Vec3 w = x - origin;
    std::fprintf(f, " %.6g %.6g %.6g", 1e3 * w.dot(direction), 1e3 * w.dot(up), 1e3 * w.dot(aside));
  };
  for (const SweptTriangle& t : sweep) {
    std::fprintf(f, "S");
    for (const Vec3& x : t.x) point(x);
    std::fprintf(f, "\n");
  }
  for (const BoundaryTriangle& t : extract_boundary_surface(mesh).triangles) {
    if (!t.cut) continue;
    std::fprintf(f, "C");
    for (int n : t.nodes) point(mesh.nodes[static_cast<size_t>(n)]);
    std::fprintf(f, "\n");
  }
  for (int t = 0; t < mesh.num_tets(); ++t)
    for (int k = 0; k < 4; ++k)
      if (mesh.is_cut_face(t, k)) {
        std::fprintf(f, "M");
        for (int j = 0; j < 4; ++j)
          if (j != k) point(mesh.nodes[static_cast<size_t>(mesh.tets[t][j])]);
        std::fprintf(f, "\n");
      }
  if (tets)
    for (int t = 0; t < mesh.num_tets(); ++t) {
      std::fprintf(f, "T");
      for (int n : mesh.tets[t]) std::fprintf(f, " %d", n);
      for (int n : mesh.tets[t]) point(mesh.nodes[static_cast<size_t>(n)]);
      std::fprintf(f, "\n");
    }
  return std::fclose(f) == 0;
}

}  // namespace stc
