#include "cutting/vertex_insertion.hpp"

#include "cutting/triangle_cut.hpp"
#include "soft_tissue_cutting/collision/tet_locator.hpp"
#include "soft_tissue_cutting/mesh/quality.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace stc {
namespace {

const Vec3& corner(const TetMesh& mesh, int v, const Vec3& point) {
  return v == kInsertedNode ? point : mesh.nodes[static_cast<size_t>(v)];
}

double volume_with(const TetMesh& mesh, const Tet& k, const Vec3& point) {
  return signed_volume(corner(mesh, k[0], point), corner(mesh, k[1], point),
                       corner(mesh, k[2], point), corner(mesh, k[3], point));
}

double angle_with(const TetMesh& mesh, const Tet& k, const Vec3& point) {
  return smallest_dihedral_deg(corner(mesh, k[0], point), corner(mesh, k[1], point),
                               corner(mesh, k[2], point), corner(mesh, k[3], point));
}

// The new tets' smallest dihedral angle with the node at `point`; -1 if one of them is not
// above min_volume.
double quality_at(const TetMesh& mesh, const std::vector<Tet>& tets, const Vec3& point,
                  double min_volume) {
  double q = 180;
  for (const Tet& k : tets) {
    if (!(volume_with(mesh, k, point) > min_volume)) return -1;
    q = std::min(q, angle_with(mesh, k, point));
  }
  return q;
}

// How far `point` lies inside the cavity's boundary: the least height over a boundary face
// (signed: negative on its outer side) in units of the face's longest edge; `towards` (if
// given) is that face's inward normal, the direction that raises it.
double clearance(const TetMesh& mesh, const std::vector<Tet>& tets, const Vec3& point,
                 Vec3* towards) {
  double least = 1e300;
  for (const Tet& k : tets) {
    const Vec3* face[3];
    int n = 0;
    for (int v : k)
      if (v != kInsertedNode) face[n++] = &mesh.nodes[static_cast<size_t>(v)];
    const Vec3 normal = (*face[1] - *face[0]).cross(*face[2] - *face[0]);
    const double longest = std::max(
        {(*face[1] - *face[0]).norm(), (*face[2] - *face[1]).norm(), (*face[0] - *face[2]).norm()});
    const double volume = volume_with(mesh, k, point);
    const double height = 6 * volume / normal.norm() / longest;
    if (height < least) {
      least = height;
      // The new tet's volume is affine in the point, with gradient +-normal / 6: which sign
      // from the volume at the face's centroid (zero) and at the point.
      if (towards) {
        const Vec3 centroid = (*face[0] + *face[1] + *face[2]) / 3;
        const double slope = normal.dot(point - centroid);
        *towards = (slope * volume >= 0 ? 1.0 : -1.0) * normal.normalized();
        if (slope == 0)
          *towards = volume_with(mesh, k, point + normal) > volume ? Vec3(normal.normalized())
                                                                   : Vec3(-normal.normalized());
      }
    }
  }
  return least;
}

// An ascent on a max-min measure of the point (eq. (20b)'s): from x, along what raises the
// worst term, with a step that grows on success and halves on failure. measure(p, &direction)
// returns the measure and the direction.
template <typename Measure>
Vec3 ascend(Vec3 x, double scale, const Measure& measure) {
  Vec3 along;
  double value = measure(x, &along);
  double step = 0.05 * scale;
  for (int iteration = 0; iteration < 60 && step > 1e-3 * scale && along != Vec3::Zero();
       ++iteration) {
    Vec3 next_along;
    const Vec3 y = x + step * along;
    const double next = measure(y, &next_along);
    if (next > value + 1e-9) {
      x = y, value = next, along = next_along;
      step = std::min(1.5 * step, 0.5 * scale);
    } else {
      step *= 0.5;
    }
  }
  return x;
}

// The cavity's description and its new tets (one per boundary face, with kInsertedNode): false
// if a tet of it is not cuttable, a face inside it is on a cut or a corner lies inside it.
bool describe_cavity(const TetMesh& mesh, const CutState& state, std::vector<int> cavity,
                     VertexInsertion& insertion, double& volume, double& flattest,
                     double& shortest) {
  std::sort(cavity.begin(), cavity.end());
  cavity.erase(std::unique(cavity.begin(), cavity.end()), cavity.end());
  insertion = VertexInsertion{};
  insertion.cavity = cavity;
  insertion.before = 180;
  insertion.size_class = 1e300;
  volume = 0, flattest = 1e300, shortest = 1e300;
  std::set<int> corners, on_boundary;
  for (int c : cavity) {
    if (!state.cuttable[static_cast<size_t>(c)]) return false;
    const Tet& k = mesh.tets[static_cast<size_t>(c)];
    const Vec3 &a = mesh.nodes[k[0]], &b = mesh.nodes[k[1]], &d = mesh.nodes[k[2]],
               &e = mesh.nodes[k[3]];
    insertion.before = std::min(insertion.before, smallest_dihedral_deg(a, b, d, e));
    insertion.size_class =
        std::min(insertion.size_class, state.origin_volume[static_cast<size_t>(c)]);
    flattest = std::min(flattest, volume_ratio(a, b, d, e));
    volume += tet_volume(mesh, c);
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        shortest = std::min(shortest, (mesh.nodes[k[i]] - mesh.nodes[k[j]]).norm());
    for (int f = 0; f < 4; ++f) {
      corners.insert(k[static_cast<size_t>(f)]);
      const int across = neighbour_across(mesh, state, c, f).first;
      if (across >= 0 && std::binary_search(cavity.begin(), cavity.end(), across)) {
        if (mesh.is_cut_face(c, f)) return false;  // a cut inside the cavity would vanish
        continue;
      }
      Tet joined = k;  // the face with the new node instead of c's opposite corner: positive
      joined[static_cast<size_t>(f)] = kInsertedNode;
      insertion.tets.push_back(joined);
      for (int i : kTetFaces[static_cast<size_t>(f)]) on_boundary.insert(k[static_cast<size_t>(i)]);
    }
  }
  return on_boundary.size() == corners.size();  // a corner inside would be lost
}

// The new tets' total volume equals the cavity's (to 1e-12: they tile it) and the cavity tet
// that holds `x` (the most inside one: round-off on a shared face) with x's weights in it.
bool tiles_and_locate(const TetMesh& mesh, const Vec3& x, double volume,
                      VertexInsertion& insertion) {
  double tiled = 0;
  for (const Tet& k : insertion.tets) tiled += volume_with(mesh, k, x);
  if (std::abs(tiled - volume) > 1e-12 * volume) return false;
  double inside = -1e300;
  for (int c : insertion.cavity) {
    const Tet& k = mesh.tets[static_cast<size_t>(c)];
    const std::array<double, 4> w =
        barycentric(mesh.nodes[k[0]], mesh.nodes[k[1]], mesh.nodes[k[2]], mesh.nodes[k[3]], x);
    if (const double least = *std::min_element(w.begin(), w.end()); least > inside)
      inside = least, insertion.host = k, insertion.weights = w;
  }
  insertion.point = x;
  return inside > -1e-9;
}

}  // namespace

bool vertex_insertion(const TetMesh& mesh, const CutState& state, std::vector<int> cavity,
                      double guard, VertexInsertion& insertion) {
  double volume = 0, flattest = 0, shortest = 0;
  if (!describe_cavity(mesh, state, std::move(cavity), insertion, volume, flattest, shortest))
    return false;
  // Where every new tet is positive, if anywhere: the point deepest inside every boundary
  // face, found from the best cavity tet's centroid.
  Vec3 x = Vec3::Zero();
  double deepest = -1e300;
  for (int c : insertion.cavity) {
    Vec3 centroid = Vec3::Zero();
    for (int v : mesh.tets[static_cast<size_t>(c)])
      centroid += mesh.nodes[static_cast<size_t>(v)] / 4;
    const double depth = clearance(mesh, insertion.tets, centroid, nullptr);
    if (depth > deepest) deepest = depth, x = centroid;
  }
  x = ascend(x, shortest,
             [&](const Vec3& p, Vec3* along) { return clearance(mesh, insertion.tets, p, along); });
  const double min_volume = guard * insertion.size_class;
  if (!(quality_at(mesh, insertion.tets, x, min_volume) > 0)) return false;
  // Then the best smallest angle (its direction: the worst new tet's gradient, by central
  // differences), staying valid.
  const double eps = 1e-4 * shortest;
  x = ascend(x, shortest, [&](const Vec3& p, Vec3* along) {
    const double q = quality_at(mesh, insertion.tets, p, min_volume);
    const Tet* worst = &insertion.tets.front();
    double worst_angle = 1e300;
    for (const Tet& k : insertion.tets)
      if (const double angle = angle_with(mesh, k, p); angle < worst_angle)
        worst_angle = angle, worst = &k;
    Vec3 gradient;
    for (int i = 0; i < 3; ++i) {
      Vec3 up = p, down = p;
      up[i] += eps;
      down[i] -= eps;
      gradient[i] = (angle_with(mesh, *worst, up) - angle_with(mesh, *worst, down)) / (2 * eps);
    }
    *along = gradient.norm() > 0 ? Vec3(gradient.normalized()) : Vec3::Zero();
    return q;
  });
  insertion.after = quality_at(mesh, insertion.tets, x, min_volume);
  if (!(insertion.after > 0)) return false;
  double flattest_new = 1e300;
  for (const Tet& k : insertion.tets)
    flattest_new =
        std::min(flattest_new, volume_ratio(corner(mesh, k[0], x), corner(mesh, k[1], x),
                                            corner(mesh, k[2], x), corner(mesh, k[3], x)));
  if (flattest_new < flattest) return false;
  return tiles_and_locate(mesh, x, volume, insertion);
}

bool vertex_insertion_at(const TetMesh& mesh, const CutState& state, std::vector<int> cavity,
                         const std::vector<Vec3>& points, double guard, double min_angle_deg,
                         VertexInsertion& insertion) {
  double volume = 0, flattest = 0, shortest = 0;
  if (!describe_cavity(mesh, state, std::move(cavity), insertion, volume, flattest, shortest))
    return false;
  const double min_volume = guard * insertion.size_class;
  const Vec3* best = nullptr;
  insertion.after = -1;
  for (const Vec3& p : points)
    if (const double q = quality_at(mesh, insertion.tets, p, min_volume); q > insertion.after)
      insertion.after = q, best = &p;
  // The new tet that is worst there (the first not above the size guard, else the flattest):
  // a larger cavity may replace its face.
  const Vec3& at = best ? *best : points.front();
  double worst = 1e300;
  for (size_t i = 0; i < insertion.tets.size(); ++i) {
    const Tet& k = insertion.tets[i];
    const double angle = volume_with(mesh, k, at) > min_volume ? angle_with(mesh, k, at) : -1.0;
    if (angle < worst) worst = angle, insertion.worst = static_cast<int>(i);
    if (angle < 0) break;
  }
  if (!best || !(insertion.after >= min_angle_deg) || !(insertion.after > 0)) return false;
  return tiles_and_locate(mesh, *best, volume, insertion);
}

bool vertex_insertion_growing(const TetMesh& mesh, const CutState& state, std::vector<int> cavity,
                              const std::vector<Vec3>& points, double guard, double min_angle_deg,
                              const std::vector<std::pair<int, int>>& keep, int max_growth,
                              VertexInsertion& insertion) {
  for (int grow = 0; grow <= max_growth; ++grow) {
    if (vertex_insertion_at(mesh, state, cavity, points, guard, min_angle_deg, insertion))
      return true;
    if (grow == max_growth || insertion.worst < 0) return false;
    FaceKey face{};
    int n = 0;
    for (int w : insertion.tets[static_cast<size_t>(insertion.worst)])
      if (w != kInsertedNode && n < 3) face[static_cast<size_t>(n++)] = w;
    std::sort(face.begin(), face.end());
    int across = -1;
    for (int c : insertion.cavity)
      for (int f = 0; f < 4 && across < 0; ++f)
        if (face_key(mesh.tets[static_cast<size_t>(c)], f) == face && !mesh.is_cut_face(c, f))
          across = neighbour_across(mesh, state, c, f).first;
    if (across < 0) return false;
    const Tet& k = mesh.tets[static_cast<size_t>(across)];
    for (const auto& e : keep)
      if (std::count(k.begin(), k.end(), e.first) && std::count(k.begin(), k.end(), e.second))
        return false;
    cavity = insertion.cavity;
    cavity.push_back(across);
  }
  return false;
}

bool star_from_corner(const TetMesh& mesh, const CutState& state, std::vector<int> cavity, int apex,
                      double guard, double min_angle_deg, VertexInsertion& insertion) {
  double volume = 0, flattest = 0, shortest = 0;
  if (!describe_cavity(mesh, state, std::move(cavity), insertion, volume, flattest, shortest))
    return false;
  // The apex's own boundary faces stay faces (of the tets joining it to the faces beside them);
  // the others are joined to it. The apex must be a corner of the cavity: a star from a point
  // inside would be an insertion.
  const size_t faces = insertion.tets.size();
  insertion.tets.erase(
      std::remove_if(insertion.tets.begin(), insertion.tets.end(),
                     [&](const Tet& k) { return std::count(k.begin(), k.end(), apex) > 0; }),
      insertion.tets.end());
  if (insertion.tets.size() == faces || insertion.tets.size() < insertion.cavity.size())
    return false;
  const Vec3& at = mesh.nodes[static_cast<size_t>(apex)];
  insertion.after = quality_at(mesh, insertion.tets, at, guard * insertion.size_class);
  if (!(insertion.after >= min_angle_deg) || !(insertion.after > 0)) return false;
  if (!tiles_and_locate(mesh, at, volume, insertion)) return false;
  for (Tet& k : insertion.tets)
    for (int& v : k)
      if (v == kInsertedNode) v = apex;
  return true;
}

bool joins_edges_at(const VertexInsertion& insertion, int apex,
                    const std::vector<std::pair<int, int>>& edges) {
  return std::all_of(edges.begin(), edges.end(), [&](const std::pair<int, int>& e) {
    for (const Tet& k : insertion.tets)
      if (std::count(k.begin(), k.end(), apex) && std::count(k.begin(), k.end(), e.first) &&
          std::count(k.begin(), k.end(), e.second))
        return true;
    return false;
  });
}

bool joins_edges(const VertexInsertion& insertion, const std::vector<std::pair<int, int>>& edges) {
  return joins_edges_at(insertion, kInsertedNode, edges);
}

std::vector<std::vector<int>> insertion_cavities(const TetMesh& mesh, const CutState& state,
                                                 int t) {
  std::vector<std::vector<int>> cavities;
  std::vector<int> around = {t};
  for (int f = 0; f < 4; ++f) {
    if (mesh.is_cut_face(t, f)) continue;
    const int across = neighbour_across(mesh, state, t, f).first;
    if (across >= 0) around.push_back(across);
  }
  cavities.push_back(std::move(around));
  const Tet& k = mesh.tets[static_cast<size_t>(t)];
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      std::vector<int> ring =
          tets_with_edge(state, k[static_cast<size_t>(i)], k[static_cast<size_t>(j)]);
      if (ring.size() >= 3 && ring.size() <= 10) cavities.push_back(std::move(ring));
    }
  return cavities;
}

}  // namespace stc
