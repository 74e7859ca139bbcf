// The scene of docs/SCENE.md "Scene file", as data. Loading and validation: scene_loader.hpp.
#pragma once

#include "soft_tissue_cutting/mesh/tet_mesh.hpp"
#include "soft_tissue_cutting/solve/backend.hpp"

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

namespace stc {

struct Box {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();
  bool contains(const Vec3& p) const {  // boundary included
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

struct Sphere {
  Vec3 center = Vec3::Zero();
  double radius = 0;
  bool contains(const Vec3& p) const { return (p - center).norm() <= radius; }
};

// A set of nodes: explicit 0-based indices, a box or a sphere.
struct NodeSelector {
  enum class Kind { kNodes, kBox, kSphere } kind = Kind::kNodes;
  std::vector<int> nodes;
  Box box;
  Sphere sphere;
  std::vector<int> select(const TetMesh& mesh) const;  // ascending, unique
};

struct Load {
  NodeSelector where;
  Vec3 force = Vec3::Zero();  // N, per node (`force`) or in total (`total_force`)
  bool total = false;         // true: split evenly over the selected nodes
};

struct Material {
  double young_modulus = 3000.0;  // Pa
  double poisson_ratio = 0.45;
  double density = 1000.0;  // kg/m^3
};

struct OperationRegion {
  // kFollow: a ball of radius `sphere.radius` around the blade that moves with it (the model
  // is re-partitioned and re-condensed around the blade, simulation/region_follower.hpp).
  // `sphere` holds where the ball starts: the first trajectory pose's tip, or the centre of
  // the mesh's bounding box when the scene has no trajectory (docs/SCENE.md "Scene file").
  enum class Kind { kSphere, kBox, kAll, kNone, kFollow } kind = Kind::kAll;
  Sphere sphere;
  Box box;
  bool contains(const Vec3& centroid) const;
  bool follows_blade() const { return kind == Kind::kFollow; }
};

// The largest shape guard (degrees) the scene key, the live setter and the node accept: above
// it most splits of a good mesh would be refused (a regular tet's angles are 70.5 deg, and a
// bisection halves some of them), so the cut would no longer follow the blade.
constexpr double kMaxShapeGuardDeg = 30;

struct ScalpelParams {
  double blade_length = 0.02;  // m, edge from the tip along local +x
  double cut_pressure = 0.5;   // N
  // Degrees; 0: off. The cutter's shape guard (CutOptions::split_min_dihedral_deg): no cut
  // makes a tet thinner than this or than the one it splits, at the cost of following the
  // blade less closely (docs/DESIGN.md section 8, "Shape guard"). Extension of this package.
  // The default, 5 deg (1 before stop 51), keeps every tet a cut makes above 5 deg (or above the
  // tet it split) at no measured fidelity cost on the issue 9 stroke matrix; a mesh without a
  // quality bound (TetGen -pQ) is cut with gaps at 5 and wants 1 (docs/SCENE.md). A Simulation
  // takes this value.
  double shape_guard_deg = 5;
};

// A blade pose in the scene frame: origin = blade tip, local +x = cutting edge, local y =
// blade normal.
struct BladePose {
  double t = 0;
  Vec3 position = Vec3::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

// The one check of a pose (scene trajectories, ~parent_transform, scalpel topic and tf2 poses,
// ~cut paths, Simulation): why `position` + quaternion (x y z w) cannot be a pose: "not finite
// (NaN/Inf)", "zero quaternion" (|q|^2 <= 1e-12, no rotation to normalise), or "" when it can.
std::string pose_problem(const Vec3& position, const Eigen::Vector4d& quaternion_xyzw);
std::string pose_problem(const BladePose& pose);
// The rotation of a quaternion that passed pose_problem: q / |q|.
Eigen::Quaterniond unit_quaternion(const Eigen::Vector4d& quaternion_xyzw);

struct SolverParams {
  Backend backend = Backend::kCpu;
  double tolerance = 1e-10;  // relative residual ||b - Ax|| / ||b||
  int max_iterations = 2000;
};

// Parameters of the built-in generators (docs/SCENE.md "Scene file", `mesh.generator`).
struct GeneratorParams {
  std::string type;  // "thigh" or "box"
  // thigh: a thick tube along z; the inner wall is the removed thighbone.
  double inner_radius = 0.015;
  double outer_radius = 0.06;
  double length = 0.096;    // 8 cells of 12 mm: near-cubic cells at the default resolution
  double resolution = 1.0;  // multiplies the number of cells along each direction
  // box
  Vec3 size = Vec3(0.1, 0.02, 0.02);
  std::array<int, 3> cells = {10, 2, 2};
};

struct Scene {
  std::string source;     // file path the scene came from, or "thigh"
  std::string mesh_file;  // resolved path, empty when generated
  std::optional<GeneratorParams> generator;
  double scale = 1.0;
  TetMesh mesh;  // loaded/generated, scaled
  Material material;
  std::vector<NodeSelector> fixed;
  std::vector<Load> loads;
  Vec3 gravity = Vec3::Zero();
  OperationRegion operation_region;
  ScalpelParams scalpel;
  std::vector<BladePose> trajectory;
  SolverParams solver;
  // `mesh.tetgen.switches` used for a surface mesh file (empty: MeshReadOptions' default).
  std::string tetgen_switches;
  // Non-fatal findings while loading (e.g. the mesh's tets were flipped), one line each.
  std::vector<std::string> warnings;
};

}  // namespace stc
