#include "cutting/tip_corner.hpp"

#include "cutting/tet_flips.hpp"
#include "cutting/triangle_cut.hpp"
#include "cutting/vertex_insertion.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/collision/tet_locator.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace stc {
namespace {

// Samples per triangle side when looking for the tets a corner's triangle passes through:
// centroids of an n x n subdivision, strictly inside it (its edge on the border is not crossed).
constexpr int kSamplesPerSide = 24;
// The node's places tried: rings about the tip (a quarter disc, kPlaceAngles steps of angle).
constexpr int kPlaceRings = 4;
constexpr int kPlaceAngles = 8;
// How many tets the cavity may grow by when a new tet is too thin.
constexpr int kMaxGrowth = 4;
// How many of the cut's nodes nearest the tip are tried as the corner's apex.
constexpr size_t kMaxApexes = 4;

bool holds_point(const TetMesh& mesh, int t, const Vec3& p) {
  const Tet& k = mesh.tets[static_cast<size_t>(t)];
  const std::array<double, 4> w =
      barycentric(mesh.nodes[k[0]], mesh.nodes[k[1]], mesh.nodes[k[2]], mesh.nodes[k[3]], p);
  return std::all_of(w.begin(), w.end(), [](double x) { return x >= -1e-9; });  // NaN: flat
}

// A border edge (a, b) of the cut facing the tip, the triangle (tip, a, b) filling the corner
// between them, and its angles about the tip in the blade's plane.
struct CornerTriangle {
  int a = -1, b = -1;
  double distance = 0;  // tip to the segment
  double from = 0, to = 0;
};

double angle_in_plane(const Vec3& d, const Vec3& u, const Vec3& v) {
  return std::atan2(d.dot(v), d.dot(u));
}

bool arcs_overlap(const CornerTriangle& p, const CornerTriangle& q) {
  // Each arc is shorter than pi (a triangle's angle): overlap iff a midpoint lies within the
  // other's half-width (angles wrapped).
  const auto wrap = [](double x) { return std::remainder(x, 2 * M_PI); };
  const double mp = p.from + 0.5 * wrap(p.to - p.from), mq = q.from + 0.5 * wrap(q.to - q.from);
  const double hp = 0.5 * std::abs(wrap(p.to - p.from)), hq = 0.5 * std::abs(wrap(q.to - q.from));
  return std::abs(wrap(mp - mq)) < hp + hq - 1e-9;
}

}  // namespace

int fill_tip_corner(TetMesh& mesh, CutState& state, const Vec3& tip,
                    const std::vector<std::array<Vec3, 3>>& band, const CutOptions& options,
                    CutResult& result) {
  const double margin = state.stroke_margin;
  if (!(margin > 0) || !tip.allFinite()) return -1;
  // The blade's plane where it stopped: the band's tip-side triangle that holds the blade's
  // last edge (cut_band's (A0, B1, B0); a curved stroke's band is twisted).
  if (band.size() < 2) return -1;
  const auto& last = band[1];
  Vec3 normal = (last[1] - last[0]).cross(last[2] - last[0]);
  if (!(normal.norm() > 0)) return -1;  // a plunge sweeps nothing
  normal.normalize();
  const Vec3 u = (last[1] - last[2]).normalized(), v = normal.cross(u);
  bool in_tissue = false;
  for (int t : state.grid.query(mesh, tip, tip)) in_tissue = in_tissue || holds_point(mesh, t, tip);
  if (!in_tissue) return -1;
  // The margin is a quarter of the band's mean edge (CutOptions::front_margin_fraction): an
  // element's reach is four of them.
  const double reach = 4 * margin, snap = options.snap_tolerance * reach;
  const std::vector<int> near =
      state.grid.query(mesh, tip - Vec3::Constant(reach), tip + Vec3::Constant(reach));
  // The marked faces near the tip: covered already (an opened one within a margin), or their
  // edges facing it. The stroke's end has opened what it can before (finish_stroke), so a mark
  // still closed stays so: it covers nothing, and a triangle may hang on it. (Up to stop 55 the
  // fill came first and only opened walls counted: hung on a mark still to open, the triangle
  // stacked marks whose corners all lie on the border, and on the fine liver2's tilted straight
  // 3 mm stroke every mark at the tip stayed shut.)
  // edge -> every mark on it lies away from the tip
  std::map<std::pair<int, int>, bool> facing;
  for (int t : near)
    for (int f = 0; f < 4; ++f) {
      if (!mesh.is_cut_face(t, f)) continue;
      const FaceKey key = face_key(mesh.tets[static_cast<size_t>(t)], f);
      Vec3 w;
      const Vec3 closest = closest_point_on_triangle(tip, mesh.nodes[key[0]], mesh.nodes[key[1]],
                                                     mesh.nodes[key[2]], w);
      const bool opened = neighbour_across(mesh, state, t, f).first < 0;
      if (opened && (closest - tip).norm() <= margin) return -1;
      for (int e = 0; e < 3; ++e) {
        const int a = std::min(key[e], key[(e + 1) % 3]), b = std::max(key[e], key[(e + 1) % 3]);
        const Vec3 &xa = mesh.nodes[a], &xb = mesh.nodes[b], &xc = mesh.nodes[key[(e + 2) % 3]];
        const double tip_side = normal.dot((xb - xa).cross(tip - xa)),
                     mark_side = normal.dot((xb - xa).cross(xc - xa));
        auto it = facing.emplace(std::make_pair(a, b), true).first;
        it->second = it->second && tip_side * mark_side < 0;
      }
    }
  // The corner's triangles: each border edge facing the tip, on the plane (within the snap
  // distance), an element at most away, more than a margin from it; nearest first, as a fan
  // whose triangles do not overlap.
  std::vector<CornerTriangle> candidates;
  for (const auto& [edge, away] : facing) {
    if (!away) continue;
    const Vec3 &xa = mesh.nodes[edge.first], &xb = mesh.nodes[edge.second];
    if ((xa - tip).norm() > reach || (xb - tip).norm() > reach) continue;
    if (std::abs(normal.dot(xa - tip)) > snap || std::abs(normal.dot(xb - tip)) > snap) continue;
    CornerTriangle c;
    c.a = edge.first, c.b = edge.second;
    c.distance = (closest_point_on_segment(xa, xb, tip) - tip).norm();
    if (!(c.distance > margin)) continue;
    c.from = angle_in_plane(xa - tip, u, v), c.to = angle_in_plane(xb - tip, u, v);
    candidates.push_back(c);
  }
  std::sort(
      candidates.begin(), candidates.end(),
      [](const CornerTriangle& p, const CornerTriangle& q) { return p.distance < q.distance; });
  std::vector<CornerTriangle> fan;
  for (const CornerTriangle& c : candidates)
    if (std::none_of(fan.begin(), fan.end(),
                     [&](const CornerTriangle& f) { return arcs_overlap(c, f); }))
      fan.push_back(c);
  if (fan.empty()) return -1;
  // Where the node may go: on the blade's plane, within a margin of the tip, behind its front
  // and above its path (inside the sweep), the place that makes the best tets.
  Vec3 ahead = v;
  if (ahead.dot(last[2] - last[0]) < 0) ahead = -ahead;
  std::vector<Vec3> places = {tip};
  for (int r = 1; r <= kPlaceRings; ++r)
    for (int k = 0; k <= kPlaceAngles; ++k) {
      const double angle = 0.5 * M_PI * k / kPlaceAngles, radius = margin * r / kPlaceRings;
      places.push_back(tip + radius * (std::cos(angle) * u - std::sin(angle) * ahead));
    }
  // The cavity: the tets the fan's triangles pass through. The whole fan, else its triangles
  // one by one, nearest first (a boundary face of the cavity may lie on the plane, the node
  // flat against it).
  // The tets the triangles from `from` to the fan's edges pass through.
  const auto cavity_of = [&](const std::vector<CornerTriangle>& triangles, const Vec3& from) {
    std::vector<int> cavity;
    for (const CornerTriangle& c : triangles) {
      const Vec3 &xa = mesh.nodes[c.a], &xb = mesh.nodes[c.b];
      for (int i = 0; i < kSamplesPerSide; ++i)
        for (int j = 0; i + j < kSamplesPerSide; ++j)
          for (double shift : {1.0 / 3, 2.0 / 3}) {
            if (shift > 0.5 && i + j + 1 >= kSamplesPerSide) continue;
            const Vec3 p =
                from + ((i + shift) * (xa - from) + (j + shift) * (xb - from)) / kSamplesPerSide;
            for (int t : state.grid.query(mesh, p, p))
              if (holds_point(mesh, t, p)) cavity.push_back(t);
          }
    }
    return cavity;
  };
  const auto edges_of = [](const std::vector<CornerTriangle>& triangles) {
    std::vector<std::pair<int, int>> edges;
    for (const CornerTriangle& c : triangles) edges.emplace_back(c.a, c.b);
    return edges;
  };
  const auto insert_for = [&](const std::vector<CornerTriangle>& triangles,
                              VertexInsertion& insertion) {
    const std::vector<std::pair<int, int>> edges = edges_of(triangles);
    // Every triangle must be a face of the new tets (its border edge on the cavity's
    // boundary): else the node would not fill the corner.
    return vertex_insertion_growing(mesh, state, cavity_of(triangles, tip), places,
                                    2 * options.min_volume_fraction, options.split_min_dihedral_deg,
                                    edges, kMaxGrowth, insertion) &&
           joins_edges(insertion, edges);
  };
  std::vector<std::vector<CornerTriangle>> tries = {fan};
  if (fan.size() > 1)
    for (const CornerTriangle& c : fan) tries.push_back({c});
  VertexInsertion insertion;
  auto chosen = std::find_if(tries.begin(), tries.end(), [&](const auto& triangles) {
    return insert_for(triangles, insertion);
  });
  // Else a node of the cut already near the tip (eq. (19d')): a node there makes tets too thin
  // when one lies there already, short of the fan's edges by a tet that no face on the plane
  // crosses (the thigh's curved vertical 0.2 mm stroke: a node 0.6 mm from the tip, its nearest
  // open face 5 mm away). The tets the triangles from it pass through are retriangulated as its
  // star where that keeps the guards; the nearest such node first, the whole fan first.
  const auto from_node = [&]() {
    std::vector<std::pair<double, int>> apexes;
    for (int t : near)
      for (int w : mesh.tets[static_cast<size_t>(t)]) {
        const Vec3& x = mesh.nodes[static_cast<size_t>(w)];
        if ((x - tip).norm() <= margin && is_on_stroke(state, w) &&
            std::abs(normal.dot(x - tip)) <= snap)
          apexes.emplace_back((x - tip).norm(), w);
      }
    std::sort(apexes.begin(), apexes.end());
    apexes.erase(std::unique(apexes.begin(), apexes.end()), apexes.end());
    for (size_t k = 0; k < apexes.size() && k < kMaxApexes; ++k) {
      const int apex = apexes[k].second;
      for (const auto& triangles : tries) {
        if (std::any_of(triangles.begin(), triangles.end(),
                        [&](const CornerTriangle& c) { return c.a == apex || c.b == apex; }))
          continue;
        if (star_from_corner(mesh, state, cavity_of(triangles, mesh.nodes[apex]), apex,
                             2 * options.min_volume_fraction, options.split_min_dihedral_deg,
                             insertion) &&
            joins_edges_at(insertion, apex, edges_of(triangles))) {
          apply_star(mesh, state, insertion, result);
          fan = triangles;
          return apex;
        }
      }
    }
    return -1;
  };
  int node = -1;
  if (chosen != tries.end()) {
    fan = *chosen;
    node = apply_insertion(mesh, state, insertion, result, false);
  } else if (options.tip_corner_from_node) {
    node = from_node();
  }
  if (node < 0) return -1;
  set_on_stroke(state, node);
  // Its corners all lie on the cut's border, so each triangle marked stays closed until the
  // stroke's end gives it a corner inside the cut (closed_marks.hpp). (A node inside the
  // triangle at once, its two tets split at a point of it, would open it here: on the thigh's
  // curved 45-degree stroke the best such split left a 2.9 deg tet, under the guard.)
  for (int t : state.node_tets[static_cast<size_t>(node)])
    for (int f = 0; f < 4; ++f) {
      const FaceKey key = face_key(mesh.tets[static_cast<size_t>(t)], f);
      for (const CornerTriangle& c : fan)
        if (std::count(key.begin(), key.end(), node) && std::count(key.begin(), key.end(), c.a) &&
            std::count(key.begin(), key.end(), c.b))
          mesh.cut_faces[static_cast<size_t>(t)] |= static_cast<std::uint8_t>(1u << f);
    }
  return node;
}

}  // namespace stc
