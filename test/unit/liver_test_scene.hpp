// The SOFA livers as test scenes (config/meshes/MESHES.md), shared by the CalculiX and the
// hybrid-vs-full tests. sofa_liver: SOFA's own demo supports (1-based nodes 3 39 64),
// sofa_liver2: the 10% lowest-x nodes fixed. E = 3000, nu = 0.3. A point load of
// (0.5, -2, 0.3) N in total on the `loaded` nodes with the largest y, an operation sphere of
// `region_fraction` times the largest extent around the highest node. Units as in the files
// (treated as metres: a linear-algebra check, not anatomy).
#pragma once

#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/scene/scene.hpp"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace stc::testing_scenes {

inline Scene liver_scene(const std::string& file, bool gravity, int loaded, double region_fraction,
                         OperationRegion::Kind kind = OperationRegion::Kind::kSphere) {
  Scene s;
  s.source = file;
  s.mesh = read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/" + file);
  s.material = Material{3000.0, 0.3, 1000.0};
  Vec3 lo = s.mesh.nodes[0], hi = lo;
  for (const Vec3& x : s.mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  NodeSelector fixed;
  if (file == "sofa_liver.msh") {
    fixed.nodes = {2, 38, 63};
  } else {
    fixed.kind = NodeSelector::Kind::kBox;
    fixed.box =
        Box{lo - Vec3::Constant(1), Vec3(lo.x() + 0.1 * (hi.x() - lo.x()), hi.y() + 1, hi.z() + 1)};
  }
  s.fixed.push_back(fixed);
  std::vector<std::pair<double, int>> top;
  for (int n = 0; n < s.mesh.num_nodes(); ++n) top.emplace_back(-s.mesh.nodes[n].y(), n);
  std::sort(top.begin(), top.end());
  Load load;
  for (int k = 0; k < loaded; ++k) load.where.nodes.push_back(top[k].second);
  load.total = true;
  load.force = Vec3(0.5, -2.0, 0.3);
  s.loads.push_back(load);
  if (gravity) s.gravity = Vec3(0, -9.81, 0);
  s.operation_region.kind = kind;
  s.operation_region.sphere =
      Sphere{s.mesh.nodes[top[0].second], region_fraction * (hi - lo).maxCoeff()};
  return s;
}

}  // namespace stc::testing_scenes
