// Scene files (docs/SCENE.md "Scene file"): strict parsing into a local Scene that is returned only
// when everything checked out (nothing half-loaded). Order matters: the mesh is loaded and scaled
// first, because selectors, regions and poses are in the scaled scene frame.
#include "soft_tissue_cutting/scene/scene_loader.hpp"

#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "yaml_fields.hpp"

#include <cmath>
#include <filesystem>
#include <limits>

namespace stc {
namespace {

namespace fs = std::filesystem;
using scene_yaml::Fields;

// Upper bound on generated cells: far above real-time sizes, low enough that a typo such as
// cells: [1000, 1000, 1000] is refused instead of exhausting memory.
constexpr double kMaxGeneratedCells = 2e6;

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

class SceneLoader {
 public:
  explicit SceneLoader(const std::string& path) : path_(path), f_(path) {}

  Scene load() {
    YAML::Node root;
    try {
      root = YAML::LoadFile(path_);
    } catch (const YAML::BadFile&) {
      throw SceneError(path_ + ": cannot open scene file");
    } catch (const YAML::Exception& e) {
      throw SceneError(path_ + (e.mark.is_null() ? "" : ":" + std::to_string(e.mark.line + 1)) +
                       ": YAML syntax error: " + e.msg);
    }
    if (!root.IsDefined() || root.IsNull()) throw SceneError(path_ + ": scene file is empty");
    f_.check_map(root, "",
                 {"mesh", "material", "fixed", "loads", "gravity", "operation_region", "scalpel",
                  "trajectory", "solver"});
    scene_.source = path_;
    if (!root["mesh"]) f_.fail(root, "mesh", "missing (a mesh file or generator is required)");
    load_mesh(root["mesh"]);
    if (root["material"]) load_material(root["material"]);
    load_fixed(root);
    if (root["loads"]) load_loads(root["loads"]);
    if (root["gravity"]) scene_.gravity = f_.vec3(root["gravity"], "gravity");
    if (root["operation_region"]) load_region(root["operation_region"]);
    if (scene_.generator && scene_.generator->type == "thigh") {
      // Same mesh as the built-in thigh: the operation region refined for cutting. Input
      // nodes keep their indices, so `nodes:` selectors still name the same nodes.
      try {
        scene_.mesh = refine_thigh_operation_region(scene_.mesh, *scene_.generator,
                                                    scene_.operation_region, scene_.scale);
      } catch (const std::exception& e) {
        f_.fail(root["operation_region"], "operation_region", e.what());
      }
    }
    if (root["scalpel"]) load_scalpel(root["scalpel"]);
    if (root["trajectory"]) load_trajectory(root["trajectory"]);
    if (scene_.operation_region.follows_blade()) place_follow_region();
    if (root["solver"]) load_solver(root["solver"]);
    return std::move(scene_);
  }

 private:
  // ---- mesh
  void load_mesh(const YAML::Node& m) {
    f_.check_map(m, "mesh", {"file", "generator", "scale", "tetgen"});
    if (f_.count_present(m, {"file", "generator"}) != 1)
      f_.fail(m, "mesh", "needs exactly one of `file` or `generator`");
    if (m["scale"]) scene_.scale = f_.positive(m["scale"], "mesh.scale");
    if (m["tetgen"]) {
      f_.check_map(m["tetgen"], "mesh.tetgen", {"switches"});
      if (!m["file"] || (lower_extension(m["file"].Scalar()) != ".obj" &&
                         lower_extension(m["file"].Scalar()) != ".stl" &&
                         lower_extension(m["file"].Scalar()) != ".off"))
        f_.fail(m["tetgen"], "mesh.tetgen", "only applies to .obj/.stl/.off surface files");
      if (m["tetgen"]["switches"])
        scene_.tetgen_switches = f_.string(m["tetgen"]["switches"], "mesh.tetgen.switches");
    }
    if (m["file"])
      load_mesh_file(m["file"]);
    else
      load_generator(m["generator"]);

    if (scene_.scale != 1.0) {
      for (Vec3& x : scene_.mesh.nodes) x *= scene_.scale;
    }
    // Generated meshes get the same checks as files; scaling could overflow or underflow.
    if (scene_.generator || scene_.scale != 1.0) {
      try {
        validate_tet_mesh(scene_.mesh, scene_.generator ? "generated mesh" : scene_.mesh_file,
                          &scene_.warnings);
      } catch (const MeshError& e) {
        f_.fail(m, scene_.generator ? "mesh.generator" : "mesh.scale", e.what());
      }
    }
  }

  void load_mesh_file(const YAML::Node& node) {
    const std::string name = f_.string(node, "mesh.file");
    if (name.empty()) f_.fail(node, "mesh.file", "empty path");
    fs::path p(name);
    if (p.is_relative()) p = fs::path(path_).parent_path() / p;
    scene_.mesh_file = p.lexically_normal().string();
    std::error_code ec;
    if (!fs::is_regular_file(scene_.mesh_file, ec))
      f_.fail(node, "mesh.file", "no such file: " + scene_.mesh_file);
    MeshReadOptions options;
    if (!scene_.tetgen_switches.empty()) options.tetgen_switches = scene_.tetgen_switches;
    try {
      scene_.mesh = read_mesh(scene_.mesh_file, options, &scene_.warnings);
    } catch (const MeshError& e) {
      f_.fail(node, "mesh.file", e.what());
    }
  }

  void load_generator(const YAML::Node& g) {
    if (!g.IsMap() || !g["type"]) f_.fail(g, "mesh.generator", "needs a `type` (thigh or box)");
    GeneratorParams p;
    p.type = f_.string(g["type"], "mesh.generator.type");
    const std::string k = "mesh.generator.";
    if (p.type == "thigh") {
      f_.check_map(g, "mesh.generator",
                   {"type", "inner_radius", "outer_radius", "length", "resolution"});
      if (g["inner_radius"]) p.inner_radius = f_.positive(g["inner_radius"], k + "inner_radius");
      if (g["outer_radius"]) p.outer_radius = f_.positive(g["outer_radius"], k + "outer_radius");
      if (g["length"]) p.length = f_.positive(g["length"], k + "length");
      if (g["resolution"]) p.resolution = f_.positive(g["resolution"], k + "resolution");
      if (!(p.outer_radius > p.inner_radius))
        f_.fail(g, "mesh.generator", "outer_radius must exceed inner_radius");
      // Cells per direction as make_thigh_mesh counts them (2 x 13 x 6 at resolution 1).
      const double r = p.resolution;
      const double cells = std::max(1.0, std::round(2 * r)) * std::max(3.0, std::round(13 * r)) *
                           std::max(1.0, std::round(6 * r));
      if (cells > kMaxGeneratedCells)
        f_.fail(g["resolution"], k + "resolution", "too fine (more than 2e6 cells)");
    } else if (p.type == "box") {
      f_.check_map(g, "mesh.generator", {"type", "size", "cells"});
      if (g["size"]) {
        p.size = f_.vec3(g["size"], k + "size");
        for (int d = 0; d < 3; ++d)
          if (!(p.size[d] > 0)) f_.fail(g["size"], k + "size", "every size must be > 0");
      }
      if (g["cells"]) {
        const YAML::Node c = g["cells"];
        if (!c.IsSequence() || c.size() != 3)
          f_.fail(c, k + "cells", "expected a list of 3 integers");
        for (std::size_t d = 0; d < 3; ++d)
          p.cells[d] = static_cast<int>(
              f_.integer(c[d], k + "cells[" + std::to_string(d) + "]", 1, 1000000));
      }
      if (static_cast<double>(p.cells[0]) * p.cells[1] * p.cells[2] > kMaxGeneratedCells)
        f_.fail(g["cells"], k + "cells", "too many cells (more than 2e6)");
    } else {
      f_.fail(g["type"], k + "type", "unknown generator '" + p.type + "' (thigh or box)");
    }
    try {
      scene_.mesh = p.type == "thigh" ? make_thigh_mesh(p) : make_box_mesh(p);
    } catch (const std::exception& e) {
      f_.fail(g, "mesh.generator", e.what());
    }
    scene_.generator = p;
  }

  // ---- material
  void load_material(const YAML::Node& m) {
    f_.check_map(m, "material", {"young_modulus", "poisson_ratio", "density"});
    Material& mat = scene_.material;
    if (m["young_modulus"])
      mat.young_modulus = f_.positive(m["young_modulus"], "material.young_modulus");
    if (m["poisson_ratio"]) {
      mat.poisson_ratio = f_.number(m["poisson_ratio"], "material.poisson_ratio");
      if (!(mat.poisson_ratio > -1.0 && mat.poisson_ratio < 0.5))
        f_.fail(m["poisson_ratio"], "material.poisson_ratio",
                "must lie in (-1, 0.5), got " + m["poisson_ratio"].Scalar());
    }
    if (m["density"]) mat.density = f_.non_negative(m["density"], "material.density");
  }

  // ---- selectors
  NodeSelector selector(const YAML::Node& n, const std::string& key,
                        std::initializer_list<const char*> allowed) {
    f_.check_map(n, key, allowed);
    if (f_.count_present(n, {"nodes", "box", "sphere"}) != 1)
      f_.fail(n, key, "needs exactly one of `nodes`, `box` or `sphere`");
    NodeSelector s;
    if (n["nodes"]) {
      s.kind = NodeSelector::Kind::kNodes;
      const YAML::Node list = n["nodes"];
      if (!list.IsSequence() || list.size() == 0)
        f_.fail(list, key + ".nodes", "expected a non-empty list of node indices");
      for (std::size_t i = 0; i < list.size(); ++i)
        s.nodes.push_back(static_cast<int>(f_.integer(
            list[i], key + ".nodes[" + std::to_string(i) + "]", 0, scene_.mesh.num_nodes() - 1)));
    } else if (n["box"]) {
      s.kind = NodeSelector::Kind::kBox;
      s.box = box(n["box"], key + ".box");
    } else {
      s.kind = NodeSelector::Kind::kSphere;
      s.sphere = sphere(n["sphere"], key + ".sphere");
    }
    if (s.select(scene_.mesh).empty()) f_.fail(n, key, "selects no node of the mesh");
    return s;
  }

  Box box(const YAML::Node& n, const std::string& key) {
    f_.check_map(n, key, {"min", "max"});
    if (!n["min"] || !n["max"]) f_.fail(n, key, "needs `min` and `max`");
    Box b{f_.vec3(n["min"], key + ".min"), f_.vec3(n["max"], key + ".max")};
    if (!(b.min.array() <= b.max.array()).all())
      f_.fail(n, key, "min must be <= max in every axis");
    return b;
  }

  Sphere sphere(const YAML::Node& n, const std::string& key) {
    f_.check_map(n, key, {"center", "radius"});
    if (!n["center"] || !n["radius"]) f_.fail(n, key, "needs `center` and `radius`");
    return Sphere{f_.vec3(n["center"], key + ".center"), f_.positive(n["radius"], key + ".radius")};
  }

  void load_fixed(const YAML::Node& root) {
    const YAML::Node list = root["fixed"];
    if (!list || (list.IsSequence() && list.size() == 0))
      f_.fail(list ? list : root, "fixed",
              "no fixed node: at least one is needed, otherwise the model floats");
    if (!list.IsSequence()) f_.fail(list, "fixed", "expected a list of node selectors");
    for (std::size_t i = 0; i < list.size(); ++i)
      scene_.fixed.push_back(
          selector(list[i], "fixed[" + std::to_string(i) + "]", {"nodes", "box", "sphere"}));
  }

  void load_loads(const YAML::Node& list) {
    if (!list.IsSequence()) f_.fail(list, "loads", "expected a list of loads");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string key = "loads[" + std::to_string(i) + "]";
      Load load;
      load.where = selector(list[i], key, {"nodes", "box", "sphere", "force", "total_force"});
      if (f_.count_present(list[i], {"force", "total_force"}) != 1)
        f_.fail(list[i], key, "needs exactly one of `force` (per node) or `total_force`");
      load.total = static_cast<bool>(list[i]["total_force"]);
      load.force = load.total ? f_.vec3(list[i]["total_force"], key + ".total_force")
                              : f_.vec3(list[i]["force"], key + ".force");
      scene_.loads.push_back(load);
    }
  }

  // ---- operation region: `all`, `none`, {sphere: ...}, {box: ...} or {follow: {radius}}
  void load_region(const YAML::Node& n) {
    OperationRegion& r = scene_.operation_region;
    if (n.IsScalar()) {
      const std::string v = n.Scalar();
      if (v == "all")
        r.kind = OperationRegion::Kind::kAll;
      else if (v == "none")
        r.kind = OperationRegion::Kind::kNone;
      else
        f_.fail(n, "operation_region",
                "expected all, none, {sphere: ...}, {box: ...} or {follow: {radius: r}}, got '" +
                    v + "'");
      return;
    }
    f_.check_map(n, "operation_region", {"sphere", "box", "follow"});
    if (f_.count_present(n, {"sphere", "box", "follow"}) != 1)
      f_.fail(n, "operation_region", "needs exactly one of `sphere`, `box` or `follow`");
    if (n["follow"]) {
      // A ball around the blade; where it starts is placed once the trajectory is read.
      const YAML::Node& fo = n["follow"];
      f_.check_map(fo, "operation_region.follow", {"radius"});
      if (!fo["radius"]) f_.fail(fo, "operation_region.follow.radius", "missing");
      r.kind = OperationRegion::Kind::kFollow;
      r.sphere.radius = f_.positive(fo["radius"], "operation_region.follow.radius");
      return;
    }
    if (n["sphere"]) {
      r.kind = OperationRegion::Kind::kSphere;
      r.sphere = sphere(n["sphere"], "operation_region.sphere");
    } else {
      r.kind = OperationRegion::Kind::kBox;
      r.box = box(n["box"], "operation_region.box");
    }
    bool any = false;
    for (int t = 0; t < scene_.mesh.num_tets() && !any; ++t) {
      Vec3 c = Vec3::Zero();
      for (int v : scene_.mesh.tets[t]) c += scene_.mesh.nodes[v];
      any = r.contains(c / 4.0);
    }
    if (!any)
      f_.fail(n, "operation_region",
              "contains no element centroid (use `none` for no operation part)");
  }

  // `follow` before any blade pose: centred on the first trajectory pose (the blade tip where
  // the scripted scalpel starts), else on the centre of the mesh's bounding box. It may hold
  // no tet at first: the simulation moves it to the blade as soon as the blade nears tissue
  // outside it (docs/SCENE.md "Scene file").
  void place_follow_region() {
    Sphere& ball = scene_.operation_region.sphere;
    if (!scene_.trajectory.empty()) {
      ball.center = scene_.trajectory.front().position;
      return;
    }
    Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
    for (const Vec3& x : scene_.mesh.nodes) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    ball.center = scene_.mesh.nodes.empty() ? Vec3::Zero() : Vec3(0.5 * (lo + hi));
  }

  void load_scalpel(const YAML::Node& n) {
    f_.check_map(n, "scalpel", {"blade_length", "cut_pressure", "shape_guard_deg"});
    if (n["blade_length"])
      scene_.scalpel.blade_length = f_.positive(n["blade_length"], "scalpel.blade_length");
    if (n["cut_pressure"])
      scene_.scalpel.cut_pressure = f_.non_negative(n["cut_pressure"], "scalpel.cut_pressure");
    if (n["shape_guard_deg"]) {
      const double deg = f_.non_negative(n["shape_guard_deg"], "scalpel.shape_guard_deg");
      if (deg > kMaxShapeGuardDeg)
        f_.fail(n["shape_guard_deg"], "scalpel.shape_guard_deg", "must be <= 30 (degrees)");
      scene_.scalpel.shape_guard_deg = deg;
    }
  }

  void load_trajectory(const YAML::Node& list) {
    if (!list.IsSequence()) f_.fail(list, "trajectory", "expected a list of poses");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string key = "trajectory[" + std::to_string(i) + "]";
      const YAML::Node p = list[i];
      f_.check_map(p, key, {"t", "position", "orientation"});
      if (!p["t"] || !p["position"]) f_.fail(p, key, "needs `t` and `position`");
      BladePose pose;
      pose.t = f_.number(p["t"], key + ".t");
      if (!scene_.trajectory.empty() && !(pose.t > scene_.trajectory.back().t))
        f_.fail(p["t"], key + ".t", "times must be strictly increasing");
      pose.position = f_.vec3(p["position"], key + ".position");
      if (p["orientation"]) {
        const auto q = f_.numbers(p["orientation"], key + ".orientation", 4);  // qx qy qz qw
        const Eigen::Vector4d xyzw(q[0], q[1], q[2], q[3]);
        const std::string problem = pose_problem(pose.position, xyzw);
        if (!problem.empty())
          f_.fail(p["orientation"], key + ".orientation", problem + " (not a rotation)");
        pose.orientation = unit_quaternion(xyzw);
      }
      scene_.trajectory.push_back(pose);
    }
  }

  void load_solver(const YAML::Node& n) {
    f_.check_map(n, "solver", {"backend", "tolerance", "max_iterations"});
    if (n["backend"]) {
      const std::string b = f_.string(n["backend"], "solver.backend");
      const std::optional<Backend> backend = parse_backend(b);
      if (!backend)
        f_.fail(n["backend"], "solver.backend",
                std::string("must be ") + kBackendChoices + ", got '" + b + "'");
      scene_.solver.backend = *backend;
    }
    if (n["tolerance"]) scene_.solver.tolerance = f_.positive(n["tolerance"], "solver.tolerance");
    if (n["max_iterations"])
      scene_.solver.max_iterations = static_cast<int>(f_.integer(
          n["max_iterations"], "solver.max_iterations", 1, std::numeric_limits<int>::max()));
  }

  std::string path_;
  Fields f_;
  Scene scene_;
};

}  // namespace

Scene load_scene(const std::string& path_or_builtin) {
  if (path_or_builtin == "thigh") return make_thigh_scene();
  try {
    return SceneLoader(path_or_builtin).load();
  } catch (const SceneError&) {
    throw;
  } catch (const YAML::Exception& e) {
    // yaml-cpp conversions we did not anticipate still become one clear line.
    throw SceneError(path_or_builtin +
                     (e.mark.is_null() ? "" : ":" + std::to_string(e.mark.line + 1)) + ": " +
                     e.msg);
  } catch (const std::bad_alloc&) {
    throw SceneError(path_or_builtin + ": out of memory while loading the scene");
  }
}

}  // namespace stc
