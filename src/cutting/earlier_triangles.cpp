#include "cutting/earlier_triangles.hpp"

#include <algorithm>
#include <cmath>

namespace stc {
namespace {

// A triangle's plane and the barycentric coordinates of a point's projection as linear forms
// of the point (u(p) = (n . (b' x c') + p' . (n x (c' - b'))) / A, primes relative to the
// centroid g): a few products where TriangleClassification::contains projects and takes two
// cross products, run down arrays of points.
struct LinearTriangle {
  explicit LinearTriangle(const std::array<Vec3, 3>& t) : g((t[0] + t[1] + t[2]) / 3.0) {
    const Vec3 a = t[0] - g, b = t[1] - g, c = t[2] - g;
    n = (b - a).cross(c - a);
    const double area = n.norm();
    n /= area;
    u = n.cross(c - b) / area;
    v = n.cross(a - c) / area;
    u0 = n.dot(b.cross(c)) / area;
    v0 = n.dot(c.cross(a)) / area;
    // The forms' round-off (relative to the triangle's size and its distance from the origin:
    // ~1e-13 for the sweeps' thinnest triangles) is far below the margins they are used with.
    round_off = 1e-12 * (1 + g.norm());
  }
  Vec3 g, n, u, v;
  double u0 = 0, v0 = 0, round_off = 0;
};

// The faces around the cut that an earlier triangle could mark, with what does not depend on
// the triangle: open (not on a cut yet), each corner on the stroke or, off it, on the plane of
// one of the triangles (TriangleClassification::side: within 1e-9 x its longest edge), in the
// order mark_faces_on_triangle visits them (tets ascending, then faces). A face whose corner
// is on no triangle's plane is on none of them: that is most faces, found once here instead
// of once per triangle.
struct CandidateFaces {
  std::vector<int> tet, face, box;  // box: the tet's index among the looked-at tets
  // Centroid, unit normal and kOnCutSlack x the longest edge (the plane test's slack), each
  // coordinate in its own array.
  std::array<std::vector<double>, 3> centroid, normal;
  std::vector<double> reach;

  size_t size() const { return tet.size(); }
  // excess[j] <= 0 where face j may pass mark_face_on_triangle's inside, plane and facing
  // tests for the triangle (> 0 only where one of them fails: margins far above round-off).
  // The largest of the tests' excesses, not a flag: that is what vectorizes.
  void excess_over(const LinearTriangle& tri, double tol, std::vector<double>& excess) const {
    excess.resize(size());
    const double *cx = centroid[0].data(), *cy = centroid[1].data(), *cz = centroid[2].data();
    const double *nx = normal[0].data(), *ny = normal[1].data(), *nz = normal[2].data();
    const double* r = reach.data();
    double* out = excess.data();
    const double limit = -tol - 1e-6, facing = 0.5 - 1e-9, slack = 1 + 1e-6;
    const double gx = tri.g[0], gy = tri.g[1], gz = tri.g[2], round_off = tri.round_off;
    const double n0 = tri.n[0], n1 = tri.n[1], n2 = tri.n[2], u0 = tri.u0, v0 = tri.v0;
    const double ux = tri.u[0], uy = tri.u[1], uz = tri.u[2];
    const double vx = tri.v[0], vy = tri.v[1], vz = tri.v[2];
    auto larger = [](double a, double b) { return a > b ? a : b; };
    const size_t count = size();
    for (size_t j = 0; j < count; ++j) {
      const double x = cx[j] - gx, y = cy[j] - gy, z = cz[j] - gz;
      const double off = n0 * x + n1 * y + n2 * z;
      const double u = u0 + ux * x + uy * y + uz * z, v = v0 + vx * x + vy * y + vz * z;
      const double cos = n0 * nx[j] + n1 * ny[j] + n2 * nz[j];
      out[j] = larger(larger(std::abs(off) - (r[j] * slack + round_off), facing - std::abs(cos)),
                      larger(larger(limit - u, limit - v), limit - (1.0 - u - v)));
    }
  }
};

}  // namespace

std::vector<int> tets_around_cut(const TetMesh& mesh, const CutState& state, Vec3& lo, Vec3& hi) {
  const Vec3 cut_lo = lo, cut_hi = hi;
  state.grid.grow_by_overlapping(mesh, cut_lo, cut_hi, lo, hi);
  return cuttable_tets_in(mesh, state, lo, hi);
}

void mark_faces_on_earlier_triangles(TetMesh& mesh, const CutState& state,
                                     const std::vector<std::array<Vec3, 3>>& earlier,
                                     const Vec3& lo, const Vec3& hi, const CutOptions& options,
                                     StrokeSurface& surface, double skin_slack, NodeScales& scales,
                                     CutResult& result, std::set<FaceKey>& new_faces) {
  if (earlier.empty()) return;
  // The tets this cut touched overlap [lo, hi]: a face that only now appears is among them.
  Vec3 touched_lo = lo, touched_hi = hi;
  const std::vector<int> tets = tets_around_cut(mesh, state, touched_lo, touched_hi);
  std::vector<Vec3> box_lo(tets.size()), box_hi(tets.size());
  for (size_t i = 0; i < tets.size(); ++i) tet_bounds(mesh, tets[i], box_lo[i], box_hi[i]);

  // The triangles that can mark anything: not degenerate, overlapping the looked-at box
  // (a, b: their boxes clipped to it, as mark_faces_on_triangle's tets must overlap).
  struct Earlier {
    TriangleClassification classification;
    LinearTriangle linear;
    Vec3 a, b;
  };
  std::vector<Earlier> triangles;
  for (const auto& tri : earlier) {
    TriangleClassification previous(tri[0], tri[1], tri[2], options.snap_tolerance);
    if (previous.degenerate()) continue;
    Vec3 a, b;
    previous.bounds(a, b);
    a = a.cwiseMax(touched_lo);
    b = b.cwiseMin(touched_hi);
    if ((a.array() > b.array()).any()) continue;
    previous.share_scales(&scales);
    triangles.push_back({std::move(previous), LinearTriangle(tri), a, b});
  }
  if (triangles.empty()) return;

  // The nodes off the stroke that lie on some triangle's plane (as side() decides, with its
  // own scale), every node at most once.
  std::vector<int> off;
  for (int t : tets)
    for (int v : mesh.tets[t])
      if (!is_on_stroke(state, v)) off.push_back(v);
  std::sort(off.begin(), off.end());
  off.erase(std::unique(off.begin(), off.end()), off.end());
  // side() puts a node off the stroke on the plane within 1e-9 x its longest edge: a node
  // farther off than 1e-9 x the longest of them all is not (the margin covers the two normals'
  // round-off), and side() decides the rest. The mesh's bound on every edge stands for that
  // longest (a larger limit only asks side() more often): walking each node's star for it
  // cost ~0.35 ms a cut on the organ liver.
  double longest = state.longest_edge_bound;
  std::array<std::vector<double>, 3> position;
  for (int v : off) {
    if (!(state.longest_edge_bound > 0))
      longest = std::max(longest, scales.longest_edge(mesh, state, v));
    for (int k = 0; k < 3; ++k) position[k].push_back(mesh.nodes[v][k]);
  }
  const double never_on = 1e-9 * longest * (1 + 1e-6);
  std::vector<std::uint8_t> on_some(off.size(), 0);
  std::vector<double> distance(off.size());
  for (Earlier& e : triangles) {
    const LinearTriangle& l = e.linear;
    const double limit = never_on + l.round_off, gx = l.g[0], gy = l.g[1], gz = l.g[2];
    const double n0 = l.n[0], n1 = l.n[1], n2 = l.n[2];
    const double *px = position[0].data(), *py = position[1].data(), *pz = position[2].data();
    double* out = distance.data();
    const size_t count = off.size();
    for (size_t i = 0; i < count; ++i)
      out[i] = std::abs(n0 * (px[i] - gx) + n1 * (py[i] - gy) + n2 * (pz[i] - gz));
    for (size_t i = 0; i < count; ++i)
      if (distance[i] <= limit && !on_some[i] && e.classification.side(mesh, state, off[i]) == 0)
        on_some[i] = 1;
  }
  std::vector<int> on_a_plane;
  for (size_t i = 0; i < off.size(); ++i)
    if (on_some[i]) on_a_plane.push_back(off[i]);  // ascending: `off` is
  auto may_be_on = [&](int v) {
    return is_on_stroke(state, v) || std::binary_search(on_a_plane.begin(), on_a_plane.end(), v);
  };

  CandidateFaces candidates;
  for (size_t i = 0; i < tets.size(); ++i) {
    const int t = tets[i];
    const Tet& tet = mesh.tets[t];
    for (int f = 0; f < 4; ++f) {
      if (mesh.is_cut_face(t, f)) continue;  // stays on the cut
      const int p = tet[kTetFaces[f][0]], q = tet[kTetFaces[f][1]], r = tet[kTetFaces[f][2]];
      if (!may_be_on(p) || !may_be_on(q) || !may_be_on(r)) continue;
      const Vec3 &xp = mesh.nodes[p], &xq = mesh.nodes[q], &xr = mesh.nodes[r];
      candidates.tet.push_back(t);
      candidates.face.push_back(f);
      candidates.box.push_back(static_cast<int>(i));
      // As mark_face_on_triangle computes them.
      const Vec3 centroid = (xp + xq + xr) / 3.0, normal = (xq - xp).cross(xr - xp).normalized();
      for (int k = 0; k < 3; ++k) {
        candidates.centroid[k].push_back(centroid[k]);
        candidates.normal[k].push_back(normal[k]);
      }
      candidates.reach.push_back(kOnCutSlack *
                                 std::max({(xq - xp).norm(), (xr - xq).norm(), (xp - xr).norm()}));
    }
  }

  std::vector<double> excess;
  for (Earlier& e : triangles) {
    candidates.excess_over(e.linear, options.inside_tolerance, excess);
    for (size_t j = 0; j < candidates.size(); ++j) {
      if (!(excess[j] <= 0)) continue;
      const int t = candidates.tet[j], f = candidates.face[j];
      const size_t i = static_cast<size_t>(candidates.box[j]);
      if ((box_lo[i].array() > e.b.array()).any() || (e.a.array() > box_hi[i].array()).any())
        continue;
      // Its corners off the stroke on this triangle's plane: mark_face_on_triangle asks.
      mark_face_on_triangle(mesh, state, e.classification, t, f, options, surface, skin_slack,
                            result, new_faces);
    }
  }
}

}  // namespace stc
