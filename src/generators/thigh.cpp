#include "soft_tissue_cutting/generators/thigh.hpp"

#include "soft_tissue_cutting/generators/local_refinement.hpp"
#include "structured_tets.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stc {
namespace {

int scaled_count(int base, double resolution) {
  return std::max(1, static_cast<int>(std::lround(base * resolution)));
}

}  // namespace

TetMesh make_thigh_mesh(const GeneratorParams& p) {
  if (!(p.inner_radius > 0) || !(p.outer_radius > p.inner_radius) || !(p.length > 0) ||
      !(p.resolution > 0))
    throw std::invalid_argument(
        "thigh generator: need 0 < inner_radius < outer_radius, length > 0, resolution > 0");
  // Default resolution: 2 x 13 x 6 cells = 936 tets, 273 nodes; make_thigh_scene refines
  // the operation region from there. Radii are graded geometrically so every cell is close
  // to a cube (radial step ~ circumferential step), which keeps the Kuhn tets' dihedral
  // angles near the cube's 45-90 degrees.
  const int nr = scaled_count(2, p.resolution);
  const int nt = std::max(3, scaled_count(13, p.resolution));
  const int nz = scaled_count(6, p.resolution);
  TetMesh mesh;
  auto index = [&](int i, int j, int k) { return (k * nt + (j % nt)) * (nr + 1) + i; };
  mesh.nodes.resize(static_cast<size_t>((nr + 1) * nt * (nz + 1)));
  const double ratio = p.outer_radius / p.inner_radius;
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j < nt; ++j)
      for (int i = 0; i <= nr; ++i) {
        const double r = p.inner_radius * std::pow(ratio, static_cast<double>(i) / nr);
        const double theta = 2.0 * M_PI * j / nt;
        mesh.nodes[index(i, j, k)] =
            Vec3(r * std::cos(theta), r * std::sin(theta), p.length * k / nz);
      }
  detail::add_kuhn_tets(nr, nt, nz, index, mesh);
  return mesh;
}

TetMesh make_box_mesh(const GeneratorParams& p) {
  const auto& n = p.cells;
  if (n[0] < 1 || n[1] < 1 || n[2] < 1 || !(p.size.array() > 0).all())
    throw std::invalid_argument("box generator: need size > 0 and cells >= 1");
  TetMesh mesh;
  auto index = [&](int i, int j, int k) { return (k * (n[1] + 1) + j) * (n[0] + 1) + i; };
  mesh.nodes.resize(static_cast<size_t>((n[0] + 1) * (n[1] + 1) * (n[2] + 1)));
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i)
        mesh.nodes[index(i, j, k)] =
            Vec3(p.size.x() * i / n[0], p.size.y() * j / n[1], p.size.z() * k / n[2]);
  detail::add_kuhn_tets(n[0], n[1], n[2], index, mesh);
  return mesh;
}

TetMesh refine_thigh_operation_region(const TetMesh& tube, const GeneratorParams& p,
                                      const OperationRegion& region, double scale) {
  if (region.kind == OperationRegion::Kind::kAll || region.kind == OperationRegion::Kind::kNone)
    return tube;
  // The coarse structured tube's operation region is refined by TetGen to tets of at most
  // 0.25 cm^3 (at resolution 1): the condensed part comes out near the paper's 633 nodes /
  // 2134 tets, and the operation part gets the interior nodes a cut needs (only operation
  // nodes can be duplicated; interface nodes never are).
  const double h = scale / p.resolution;
  return refine_region(tube, region, 2.5e-7 * h * h * h);
}

Scene make_thigh_scene(double resolution) {
  Scene scene;
  scene.source = "thigh";
  GeneratorParams g;
  g.type = "thigh";
  g.resolution = resolution;
  scene.generator = g;
  scene.operation_region.kind = OperationRegion::Kind::kSphere;
  // A sphere centred on the outer wall at theta = 0, mid-length: the part the scalpel cuts.
  const Vec3 centre(g.outer_radius, 0.0, 0.5 * g.length);
  scene.operation_region.sphere = Sphere{centre, 0.04};
  scene.mesh = refine_thigh_operation_region(make_thigh_mesh(g), g, scene.operation_region);
  scene.material = Material{3000.0, 0.45, 1000.0};

  // The bone surface (inner wall) is fixed.
  NodeSelector bone;
  bone.kind = NodeSelector::Kind::kNodes;
  for (int i = 0; i < scene.mesh.num_nodes(); ++i) {
    const Vec3& x = scene.mesh.nodes[i];
    if (std::hypot(x.x(), x.y()) <= g.inner_radius * (1 + 1e-9)) bone.nodes.push_back(i);
  }
  scene.fixed.push_back(bone);

  // The paper's three loaded surface nodes: outer-wall nodes near the region centre, either
  // side of the planned incision (the y = 0.003 plane), pulled tangentially away from it
  // like skin under tension, so the incision gapes once it is cut.
  std::vector<std::pair<double, int>> outer;
  for (int i = 0; i < scene.mesh.num_nodes(); ++i) {
    const Vec3& x = scene.mesh.nodes[i];
    if (std::hypot(x.x(), x.y()) >= g.outer_radius * (1 - 1e-9) && std::abs(x.y() - 0.003) > 0.004)
      outer.emplace_back((x - centre).norm(), i);
  }
  std::sort(outer.begin(), outer.end());
  for (int k = 0; k < 3 && k < static_cast<int>(outer.size()); ++k) {
    Load load;
    load.where.kind = NodeSelector::Kind::kNodes;
    load.where.nodes = {outer[k].second};
    const Vec3& x = scene.mesh.nodes[outer[k].second];
    const Vec3 radial = Vec3(x.x(), x.y(), 0).normalized();
    const Vec3 tangent = Vec3::UnitZ().cross(radial) * (x.y() > 0.003 ? 1.0 : -1.0);
    load.force = 0.05 * tangent;  // N
    scene.loads.push_back(load);
  }

  scene.scalpel = ScalpelParams{0.02, 0.5};  // yields after a few mm of pressing
  // The scripted scalpel: approach the outer wall edge-first, press in, then draw the blade
  // along z through the operation region (the cut), all in the tube's frame.
  // The blade's edge runs from the tip along local +x = world +x (radially outward at
  // theta = 0), so the tip is the deepest point; the blade lies in the x-z plane, slightly
  // off the y = 0 node plane so the cut splits tets rather than only separating faces.
  const double x0 = g.outer_radius, y0 = 0.003;
  const double z0 = 0.5 * g.length - 0.02, z1 = 0.5 * g.length + 0.02;
  auto pose = [&](double t, double x, double z) {
    BladePose p;
    p.t = t;
    p.position = Vec3(x, y0, z);
    return p;
  };
  // Approach, press in (a plunge along the edge presses, it does not cut), then draw the
  // blade along z through the operation region and lift it out.
  scene.trajectory = {pose(0.0, x0 + 0.005, z0), pose(0.2, x0 - 0.004, z0),
                      pose(0.4, x0 - 0.012, z0), pose(0.6, x0 - 0.012, 0.5 * (z0 + z1)),
                      pose(0.8, x0 - 0.012, z1), pose(1.0, x0 + 0.005, z1)};
  scene.solver = SolverParams{"cpu", 1e-10, 2000};
  return scene;
}

}  // namespace stc
