// The mesh checks of docs/SCENE.md "Meshes", shared by every reader and by generated scene meshes.
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/mesh/boundary_surface.hpp"

#include "text_cursor.hpp"

#include <algorithm>
#include <cmath>

namespace stc {

void validate_tet_mesh(TetMesh& mesh, const std::string& path, std::vector<std::string>* warnings,
                       const MeshLines* lines) {
  auto node_line = [&](int i) {
    return lines && i < static_cast<int>(lines->node_line.size()) ? lines->node_line[i] : 0;
  };
  auto tet_line = [&](int t) {
    return lines && t < static_cast<int>(lines->tet_line.size()) ? lines->tet_line[t] : 0;
  };
  const int n = mesh.num_nodes();
  for (int i = 0; i < n; ++i)
    if (!mesh.nodes[i].allFinite())
      io::fail(path, node_line(i), "node " + std::to_string(i) + " has a non-finite coordinate");
  if (mesh.tets.empty()) io::fail(path, 0, "no tetrahedra in the mesh");

  int positive = 0, negative = 0, first_positive = -1, first_negative = -1;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    const Tet& tet = mesh.tets[t];
    for (int k = 0; k < 4; ++k) {
      if (tet[k] < 0 || tet[k] >= n)
        io::fail(path, tet_line(t),
                 "tetrahedron " + std::to_string(t) + " refers to node " + std::to_string(tet[k]) +
                     ", out of range [0, " + std::to_string(n) + ")");
      for (int j = 0; j < k; ++j)
        if (tet[j] == tet[k])
          io::fail(path, tet_line(t),
                   "tetrahedron " + std::to_string(t) + " uses node " + std::to_string(tet[k]) +
                       " twice");
    }
    const Vec3 &a = mesh.nodes[tet[0]], &b = mesh.nodes[tet[1]], &c = mesh.nodes[tet[2]],
               &d = mesh.nodes[tet[3]];
    const double six_v = (b - a).dot((c - a).cross(d - a));
    double longest = 0;
    for (const Vec3* p : {&a, &b, &c, &d})
      for (const Vec3* q : {&a, &b, &c, &d}) longest = std::max(longest, (*p - *q).norm());
    // Zero volume relative to the tet's own size, so the check does not depend on units.
    if (!(std::abs(six_v) > 1e-12 * longest * longest * longest))
      io::fail(path, tet_line(t),
               "tetrahedron " + std::to_string(t) + " has zero volume (its nodes are coplanar)");
    if (six_v > 0) {
      if (positive++ == 0) first_positive = t;
    } else if (negative++ == 0) {
      first_negative = t;
    }
  }
  if (positive > 0 && negative > 0) {
    const int t = negative <= positive ? first_negative : first_positive;
    io::fail(path, tet_line(t),
             "mixed tetrahedron orientation (" + std::to_string(positive) + " positive, " +
                 std::to_string(negative) + " negative; tetrahedron " + std::to_string(t) +
                 " is in the minority): inconsistent or tangled mesh");
  }
  if (negative > 0) {
    // Every tet inverted: a consistent mesh written with the other convention (docs/SCENE.md
    // "Meshes").
    for (Tet& tet : mesh.tets) std::swap(tet[2], tet[3]);
    if (warnings)
      warnings->push_back(path + ": all " + std::to_string(negative) +
                          " tetrahedra were negatively oriented; flipped");
  }

  const BoundarySurface surface = extract_boundary_surface(mesh);
  if (surface.non_manifold_faces > 0)
    io::fail(path, 0,
             std::to_string(surface.non_manifold_faces) +
                 " face(s) shared by more than two tetrahedra or by two tetrahedra on the same "
                 "side (non-manifold, duplicated or tangled mesh)");

  std::vector<char> used(static_cast<std::size_t>(n), 0);
  for (const Tet& tet : mesh.tets)
    for (int v : tet) used[static_cast<std::size_t>(v)] = 1;
  const auto unused = std::count(used.begin(), used.end(), 0);
  if (unused > 0 && warnings) {
    const int first = static_cast<int>(std::find(used.begin(), used.end(), 0) - used.begin());
    const int line = node_line(first);
    warnings->push_back(path + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " +
                        std::to_string(unused) + " node(s) used by no tetrahedron kept (first: " +
                        std::to_string(first) + ")");
  }
}

}  // namespace stc
