// Scene loader (docs/SCENE.md "Scene file"): the example scenes, the built-in thigh, scaling before
// selectors, and a table of refused scenes whose one-line message must name the file, the key and
// the line.
#include "soft_tissue_cutting/scene/scene_loader.hpp"

#include "common/mesh_files.hpp"

#include <cmath>

namespace stc {
namespace {

using test::TempDir;
using test::write_file;

const std::string kScenes = std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/";

TEST(SceneLoader, LiverExample) {
  const Scene s = load_scene(kScenes + "liver.yaml");
  EXPECT_EQ(s.source, kScenes + "liver.yaml");
  EXPECT_NE(s.mesh_file.find("config/meshes/sofa_liver.msh"), std::string::npos);
  EXPECT_FALSE(s.generator);
  EXPECT_EQ(s.mesh.num_nodes(), 181);
  EXPECT_EQ(s.mesh.num_tets(), 596);
  EXPECT_DOUBLE_EQ(s.scale, 0.02);
  EXPECT_EQ(s.mesh.nodes[0], Vec3(-0.979259, 2.23512, 2.61245) * 0.02);
  ASSERT_EQ(s.fixed.size(), 1u);
  EXPECT_EQ(s.fixed[0].select(s.mesh), (std::vector<int>{2, 38, 63}));
  // SOFA's 1-based tag 3 is the file's third node.
  EXPECT_EQ(s.mesh.nodes[2], Vec3(-0.48104, 2.87797, 1.94243) * 0.02);
  EXPECT_EQ(s.gravity, Vec3(0, -9.81, 0));
  EXPECT_DOUBLE_EQ(s.material.poisson_ratio, 0.3);
  EXPECT_EQ(s.operation_region.kind, OperationRegion::Kind::kSphere);
  EXPECT_TRUE(s.warnings.empty());
}

TEST(SceneLoader, CantileverExample) {
  const Scene s = load_scene(kScenes + "cantilever.yaml");
  ASSERT_TRUE(s.generator);
  EXPECT_EQ(s.generator->type, "box");
  EXPECT_EQ(s.mesh.num_nodes(), 21 * 5 * 5);
  EXPECT_EQ(s.mesh.num_tets(), 20 * 4 * 4 * 6);
  EXPECT_EQ(s.fixed[0].select(s.mesh).size(), 25u);
  ASSERT_EQ(s.loads.size(), 1u);
  EXPECT_TRUE(s.loads[0].total);
  EXPECT_EQ(s.loads[0].where.select(s.mesh).size(), 25u);
  ASSERT_EQ(s.trajectory.size(), 6u);
  // The edge (local +x) points along world +z, the blade normal (local y) along world x.
  const Eigen::Matrix3d r = s.trajectory[0].orientation.toRotationMatrix();
  EXPECT_NEAR((r.col(0) - Vec3::UnitZ()).norm(), 0, 1e-12);
  EXPECT_NEAR((r.col(1) - Vec3::UnitX()).norm(), 0, 1e-12);
  EXPECT_DOUBLE_EQ(s.solver.tolerance, 1e-10);
}

TEST(SceneLoader, SurfaceAndThighExamples) {
  const Scene liver2 = load_scene(kScenes + "liver2_surface.yaml");
  EXPECT_EQ(liver2.tetgen_switches, "pq1.4/10Q");
  EXPECT_GT(liver2.mesh.num_tets(), 1000);
  EXPECT_FALSE(liver2.fixed[0].select(liver2.mesh).empty());
  const Scene thigh = load_scene(kScenes + "thigh_generated.yaml");
  const Scene builtin = load_scene("thigh");
  EXPECT_EQ(builtin.source, "thigh");
  EXPECT_EQ(thigh.mesh.nodes, builtin.mesh.nodes);
  EXPECT_EQ(thigh.mesh.tets, builtin.mesh.tets);
  EXPECT_EQ(thigh.fixed[0].select(thigh.mesh), builtin.fixed[0].select(builtin.mesh));
}

TEST(SceneLoader, DefaultsAndScaleBeforeSelectors) {
  TempDir dir;
  write_file(dir.file("box.msh"), test::gmsh_v1(test::small_box()));
  // The box is [0,2]x[0,1]x[0,1]; scaled by 3 its far corner is (6,3,3).
  const std::string path = write_file(dir.file("s.yaml"),
                                      "mesh: {file: box.msh, scale: 3}\n"
                                      "fixed: [{sphere: {center: [6, 3, 3], radius: 0.01}}]\n");
  const Scene s = load_scene(path);
  EXPECT_EQ(s.mesh_file, dir.file("box.msh"));
  EXPECT_EQ(s.fixed[0].select(s.mesh).size(), 1u);
  EXPECT_NEAR(total_volume(s.mesh), 2.0 * 27, 1e-12);
  EXPECT_EQ(s.operation_region.kind, OperationRegion::Kind::kAll);
  EXPECT_EQ(s.solver.backend, Backend::kCpu);
  EXPECT_DOUBLE_EQ(s.material.young_modulus, 3000.0);
  EXPECT_TRUE(s.trajectory.empty());
  EXPECT_EQ(s.scalpel.shape_guard_deg, 5.0);  // the default (docs/SCENE.md)
  const std::string guarded = write_file(dir.file("g.yaml"),
                                         "mesh: {file: box.msh}\n"
                                         "fixed: [{nodes: [0]}]\n"
                                         "scalpel: {shape_guard_deg: 1}\n");
  EXPECT_DOUBLE_EQ(load_scene(guarded).scalpel.shape_guard_deg, 1.0);
  const std::string unguarded = write_file(dir.file("u.yaml"),
                                           "mesh: {file: box.msh}\n"
                                           "fixed: [{nodes: [0]}]\n"
                                           "scalpel: {shape_guard_deg: 0}\n");
  EXPECT_EQ(load_scene(unguarded).scalpel.shape_guard_deg, 0.0);  // 0 turns it off
}

TEST(SceneLoader, QuaternionIsNormalizedAndFlippedMeshWarns) {
  TempDir dir;
  TetMesh box = test::small_box();
  for (Tet& t : box.tets) std::swap(t[1], t[2]);
  write_file(dir.file("box.msh"), test::gmsh_v1(box));
  const std::string path =
      write_file(dir.file("s.yaml"),
                 "mesh: {file: box.msh}\nfixed: [{nodes: [0]}]\n"
                 "trajectory:\n  - {t: 0, position: [0, 0, 0], orientation: [0, 0, 2, 0]}\n");
  const Scene s = load_scene(path);
  EXPECT_NEAR(s.trajectory[0].orientation.norm(), 1.0, 1e-15);
  EXPECT_NEAR(s.trajectory[0].orientation.z(), 1.0, 1e-15);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("flipped"), std::string::npos);
  for (int t = 0; t < s.mesh.num_tets(); ++t) EXPECT_GT(tet_volume(s.mesh, t), 0);
}

struct SceneErrorCase {
  const char* name;
  const char* yaml;     // appended to a valid mesh+fixed header unless `whole`
  const char* key;      // the message must contain "<line>: <key>" or ": <key>"
  int line;             // expected line, 0: not checked
  const char* problem;  // a fragment of the problem description
  bool whole = false;   // yaml is the whole file
};

// A header shared by most cases: lines 1-2.
const char* kHeader = "mesh: {file: box.msh}\nfixed: [{nodes: [0]}]\n";

class RefusesBadScenes : public ::testing::TestWithParam<SceneErrorCase> {};

TEST_P(RefusesBadScenes, NamesFileKeyAndLine) {
  const SceneErrorCase& c = GetParam();
  TempDir dir;
  write_file(dir.file("box.msh"), test::gmsh_v1(test::small_box()));
  std::string open = test::obj_surface(test::small_box());  // minus its last triangle
  open.erase(open.rfind("f "));
  write_file(dir.file("open.obj"), open);
  const std::string path = write_file(
      dir.file("scene.yaml"), c.whole ? std::string(c.yaml) : kHeader + std::string(c.yaml));
  try {
    load_scene(path);
    FAIL() << "loaded";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    const std::string key =
        c.line > 0 ? ":" + std::to_string(c.line) + ": " + c.key : std::string(": ") + c.key;
    EXPECT_NE(msg.find(key), std::string::npos) << msg << "\n  expected: " << key;
    EXPECT_NE(msg.find(c.problem), std::string::npos) << msg << "\n  expected: " << c.problem;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RefusesBadScenes,
    ::testing::Values(
        SceneErrorCase{"unknown_top_key", "colour: red\n", "colour", 3, "unknown key"},
        SceneErrorCase{"unknown_nested_key", "material: {young_modulus: 1, stiffness: 2}\n",
                       "material.stiffness", 3, "unknown key"},
        SceneErrorCase{"duplicate_key", "gravity: [0, 0, 0]\ngravity: [0, 0, 1]\n", "gravity", 4,
                       "duplicate"},
        SceneErrorCase{"yaml_syntax", "material: {young_modulus: [1\n", "YAML syntax error", 0, ""},
        SceneErrorCase{"empty_file", "", "scene file is empty", 0, "", true},
        SceneErrorCase{"top_not_map", "- 1\n- 2\n", "expected a map", 0, "", true},
        SceneErrorCase{"missing_mesh", "fixed: [{nodes: [0]}]\n", "mesh", 1, "missing", true},
        SceneErrorCase{"mesh_file_and_generator",
                       "mesh: {file: box.msh, generator: {type: box}}\nfixed: [{nodes: [0]}]\n",
                       "mesh", 1, "exactly one", true},
        SceneErrorCase{"missing_mesh_file", "mesh: {file: nothere.msh}\nfixed: [{nodes: [0]}]\n",
                       "mesh.file", 1, "no such file", true},
        SceneErrorCase{"open_surface", "mesh: {file: open.obj}\nfixed: [{nodes: [0]}]\n",
                       "mesh.file", 1, "not closed", true},
        SceneErrorCase{"tetgen_on_msh",
                       "mesh: {file: box.msh, tetgen: {switches: pq}}\nfixed: [{nodes: [0]}]\n",
                       "mesh.tetgen", 1, "only applies", true},
        SceneErrorCase{"bad_generator_type",
                       "mesh: {generator: {type: sphere}}\nfixed: [{nodes: [0]}]\n",
                       "mesh.generator.type", 1, "unknown generator", true},
        SceneErrorCase{"box_generator_thigh_key",
                       "mesh: {generator: {type: box, inner_radius: 1}}\nfixed: [{nodes: [0]}]\n",
                       "mesh.generator.inner_radius", 1, "unknown key", true},
        SceneErrorCase{"box_cells_zero",
                       "mesh: {generator: {type: box, cells: [1, 0, 1]}}\nfixed: [{nodes: [0]}]\n",
                       "mesh.generator.cells[1]", 1, "out of range", true},
        SceneErrorCase{
            "box_too_many_cells",
            "mesh: {generator: {type: box, cells: [1000, 1000, 1000]}}\nfixed: [{nodes: [0]}]\n",
            "mesh.generator.cells", 1, "too many", true},
        SceneErrorCase{"thigh_radii",
                       "mesh: {generator: {type: thigh, inner_radius: 0.1, outer_radius: "
                       "0.05}}\nfixed: [{nodes: [0]}]\n",
                       "mesh.generator", 1, "outer_radius", true},
        SceneErrorCase{"scale_zero", "mesh: {file: box.msh, scale: 0}\nfixed: [{nodes: [0]}]\n",
                       "mesh.scale", 1, "> 0", true},
        SceneErrorCase{"scale_string", "mesh: {file: box.msh, scale: big}\nfixed: [{nodes: [0]}]\n",
                       "mesh.scale", 1, "expected a number", true},
        SceneErrorCase{"scale_quoted",
                       "mesh: {file: box.msh, scale: \"2\"}\nfixed: [{nodes: [0]}]\n", "mesh.scale",
                       1, "expected a number", true},
        SceneErrorCase{"scale_overflow",
                       "mesh: {file: box.msh, scale: 1e308}\nfixed: [{nodes: [0]}]\n", "mesh.scale",
                       1, "non-finite", true},
        SceneErrorCase{"young_zero", "material: {young_modulus: 0}\n", "material.young_modulus", 3,
                       "> 0"},
        SceneErrorCase{"young_nan", "material: {young_modulus: .nan}\n", "material.young_modulus",
                       3, "finite"},
        SceneErrorCase{"young_inf", "material:\n  young_modulus: .inf\n", "material.young_modulus",
                       4, "finite"},
        SceneErrorCase{"nu_half", "material: {poisson_ratio: 0.5}\n", "material.poisson_ratio", 3,
                       "(-1, 0.5)"},
        SceneErrorCase{"nu_minus_one", "material: {poisson_ratio: -1}\n", "material.poisson_ratio",
                       3, "(-1, 0.5)"},
        SceneErrorCase{"density_negative", "material: {density: -1}\n", "material.density", 3,
                       ">= 0"},
        SceneErrorCase{"no_fixed", "mesh: {file: box.msh}\n", "fixed", 1, "floats", true},
        SceneErrorCase{"fixed_empty", "mesh: {file: box.msh}\nfixed: []\n", "fixed", 2, "floats",
                       true},
        SceneErrorCase{"fixed_not_list", "mesh: {file: box.msh}\nfixed: {nodes: [0]}\n", "fixed", 2,
                       "list", true},
        SceneErrorCase{"node_out_of_range", "mesh: {file: box.msh}\nfixed: [{nodes: [0, 18]}]\n",
                       "fixed[0].nodes[1]", 2, "out of range", true},
        SceneErrorCase{"node_negative", "mesh: {file: box.msh}\nfixed: [{nodes: [-1]}]\n",
                       "fixed[0].nodes[0]", 2, "out of range", true},
        SceneErrorCase{"node_not_int", "mesh: {file: box.msh}\nfixed: [{nodes: [1.5]}]\n",
                       "fixed[0].nodes[0]", 2, "integer", true},
        SceneErrorCase{
            "selector_two_kinds",
            "mesh: {file: box.msh}\nfixed: [{nodes: [0], sphere: {center: [0,0,0], radius: 1}}]\n",
            "fixed[0]", 2, "exactly one", true},
        SceneErrorCase{
            "selector_matches_nothing",
            "mesh: {file: box.msh}\nfixed:\n  - {box: {min: [5, 5, 5], max: [6, 6, 6]}}\n",
            "fixed[0]", 3, "selects no node", true},
        SceneErrorCase{"box_min_gt_max",
                       "mesh: {file: box.msh}\nfixed: [{box: {min: [1, 0, 0], max: [0, 1, 1]}}]\n",
                       "fixed[0].box", 2, "min must be <= max", true},
        SceneErrorCase{"vector_length", "gravity: [0, 0]\n", "gravity", 3, "list of 3 numbers"},
        SceneErrorCase{"vector_nan", "gravity: [0, .NaN, 0]\n", "gravity[1]", 3, "finite"},
        SceneErrorCase{"sphere_radius_negative",
                       "operation_region: {sphere: {center: [1, 0.5, 0.5], radius: -1}}\n",
                       "operation_region.sphere.radius", 3, "> 0"},
        SceneErrorCase{"region_word", "operation_region: most\n", "operation_region", 3,
                       "expected all, none"},
        SceneErrorCase{"region_empty",
                       "operation_region: {box: {min: [10, 10, 10], max: [11, 11, 11]}}\n",
                       "operation_region", 3, "no element centroid"},
        SceneErrorCase{"load_no_force", "loads: [{nodes: [1]}]\n", "loads[0]", 3, "force"},
        SceneErrorCase{"load_both_forces",
                       "loads: [{nodes: [1], force: [0,0,1], total_force: [0,0,1]}]\n", "loads[0]",
                       3, "exactly one"},
        SceneErrorCase{"load_force_length", "loads:\n  - {nodes: [1], force: [0, 1]}\n",
                       "loads[0].force", 4, "3 numbers"},
        SceneErrorCase{"blade_length_zero", "scalpel: {blade_length: 0}\n", "scalpel.blade_length",
                       3, "> 0"},
        SceneErrorCase{"cut_pressure_negative", "scalpel: {cut_pressure: -0.1}\n",
                       "scalpel.cut_pressure", 3, ">= 0"},
        SceneErrorCase{"shape_guard_negative", "scalpel: {shape_guard_deg: -1}\n",
                       "scalpel.shape_guard_deg", 3, ">= 0"},
        SceneErrorCase{"shape_guard_too_large", "scalpel: {shape_guard_deg: 45}\n",
                       "scalpel.shape_guard_deg", 3, "<= 30"},
        SceneErrorCase{"shape_guard_word", "scalpel: {shape_guard_deg: strict}\n",
                       "scalpel.shape_guard_deg", 3, "number"},
        SceneErrorCase{
            "trajectory_time_order",
            "trajectory:\n  - {t: 0.5, position: [0, 0, 0]}\n  - {t: 0.5, position: [0, 0, 1]}\n",
            "trajectory[1].t", 5, "strictly increasing"},
        SceneErrorCase{"trajectory_zero_quaternion",
                       "trajectory:\n  - {t: 0, position: [0, 0, 0], orientation: [0, 0, 0, 0]}\n",
                       "trajectory[0].orientation", 4, "zero quaternion"},
        SceneErrorCase{"trajectory_quaternion_length",
                       "trajectory:\n  - {t: 0, position: [0, 0, 0], orientation: [0, 0, 1]}\n",
                       "trajectory[0].orientation", 4, "4 numbers"},
        SceneErrorCase{"trajectory_missing_position", "trajectory:\n  - {t: 0}\n", "trajectory[0]",
                       4, "position"},
        SceneErrorCase{"backend", "solver: {backend: cuda}\n", "solver.backend", 3, "cpu or gl"},
        SceneErrorCase{"tolerance_zero", "solver: {tolerance: 0}\n", "solver.tolerance", 3, "> 0"},
        SceneErrorCase{"max_iterations_zero", "solver: {max_iterations: 0}\n",
                       "solver.max_iterations", 3, "out of range"},
        SceneErrorCase{"max_iterations_float", "solver: {max_iterations: 10.5}\n",
                       "solver.max_iterations", 3, "integer"}),
    [](const ::testing::TestParamInfo<SceneErrorCase>& info) {
      return std::string(info.param.name);
    });

TEST(SceneLoader, MissingSceneFileAndBadMeshNameTheFile) {
  try {
    load_scene("/nonexistent/scene.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/scene.yaml: cannot open scene file");
  }
  TempDir dir;
  write_file(dir.file("bad.msh"), "$NOD\n2\n1 0 0 0\n2 0 0 nan\n$ENDNOD\n");
  const std::string path =
      write_file(dir.file("s.yaml"), "mesh:\n  file: bad.msh\nfixed: [{nodes: [0]}]\n");
  try {
    load_scene(path);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()),
              path + ":2: mesh.file: " + dir.file("bad.msh") + ":4: non-finite z coordinate 'nan'");
  }
}

// One backend parser for the scene, ~backend, `tissue solve --backend` and Simulation.
TEST(SceneLoader, OneBackendParser) {
  EXPECT_EQ(parse_backend("cpu"), Backend::kCpu);
  EXPECT_EQ(parse_backend("gl"), Backend::kGl);
  EXPECT_EQ(parse_backend("cuda"), std::nullopt);
  EXPECT_EQ(parse_backend(""), std::nullopt);
  EXPECT_EQ(parse_backend("CPU"), std::nullopt);
  for (Backend b : {Backend::kCpu, Backend::kGl}) EXPECT_EQ(parse_backend(backend_name(b)), b);
}

// One pose check for trajectories, the node's poses and parent transform, and Simulation.
TEST(SceneLoader, OnePoseCheck) {
  const double nan = std::nan(""), inf = INFINITY;
  EXPECT_EQ(pose_problem(Vec3(1, 2, 3), Eigen::Vector4d(0, 0, 0, 1)), "");
  EXPECT_EQ(pose_problem(Vec3(1e300, 0, 0), Eigen::Vector4d(0, 0, 0, 2)), "");
  EXPECT_EQ(pose_problem(Vec3(nan, 0, 0), Eigen::Vector4d(0, 0, 0, 1)), "not finite (NaN/Inf)");
  EXPECT_EQ(pose_problem(Vec3(0, 0, 0), Eigen::Vector4d(0, inf, 0, 1)), "not finite (NaN/Inf)");
  EXPECT_EQ(pose_problem(Vec3(0, 0, 0), Eigen::Vector4d(0, 0, 0, 0)), "zero quaternion");
  EXPECT_EQ(pose_problem(Vec3(0, 0, 0), Eigen::Vector4d(0, 0, 0, 1e-7)), "zero quaternion");
  BladePose b;
  b.orientation.coeffs() << 0, 0, 0, 0;
  EXPECT_EQ(pose_problem(b), "zero quaternion");
  const Eigen::Quaterniond q = unit_quaternion(Eigen::Vector4d(0, 0, 3, 4));  // x y z w
  EXPECT_NEAR(q.norm(), 1, 1e-15);
  EXPECT_NEAR(q.z(), 0.6, 1e-15);
  EXPECT_NEAR(q.w(), 0.8, 1e-15);
}

}  // namespace
}  // namespace stc
