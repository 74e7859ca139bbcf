// `./tissue solve` (docs/SCENE.md "Offline run") run as a user runs it: the tissue_solve executable
// on scene files, its VTK and JSON outputs parsed and checked against the contract and against the
// full uncondensed model.
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#ifndef TISSUE_SOLVE_BIN
#error "TISSUE_SOLVE_BIN must name the tissue_solve executable (CMake defines it)"
#endif

namespace stc {
namespace {

namespace fs = std::filesystem;

// A scratch path of this process (test shards and other checkouts run at the same time).
fs::path scratch(const std::string& name) {
  return fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
}

struct SolveRun {
  int exit_code;
  std::string err;
};

// The executable CMake built, unless TISSUE_SOLVE_BIN names a copy (scripts/gpu_check.sh runs
// the binaries from another folder on a lent GPU machine, where the build tree is absent).
std::string solve_executable() {
  const char* env = std::getenv("TISSUE_SOLVE_BIN");
  return env != nullptr && *env != '\0' ? std::string(env) : std::string(TISSUE_SOLVE_BIN);
}

SolveRun run_solve(const std::string& args) {
  const fs::path err = scratch("tissue_solve_stderr.txt");
  const std::string cmd = solve_executable() + " " + args + " 2>" + err.string() + " >/dev/null";
  const int status = std::system(cmd.c_str());
  std::ifstream in(err);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

struct Vtk {
  std::vector<Vec3> points, displacement;
  std::vector<Tet> cells;
  std::vector<int> region;
};

Vtk read_output(const fs::path& path) {
  std::ifstream in(path);
  Vtk v;
  std::string word;
  while (in >> word) {
    if (word == "POINTS") {
      int n;
      in >> n >> word;
      v.points.resize(n);
      for (auto& p : v.points) in >> p.x() >> p.y() >> p.z();
    } else if (word == "CELLS") {
      int n, size;
      in >> n >> size;
      v.cells.resize(n);
      for (auto& c : v.cells) {
        int k;
        in >> k >> c[0] >> c[1] >> c[2] >> c[3];
        EXPECT_EQ(k, 4);
      }
    } else if (word == "CELL_TYPES") {
      int n;
      in >> n;
      for (int i = 0, t; i < n; ++i) {
        in >> t;
        EXPECT_EQ(t, 10);
      }
    } else if (word == "VECTORS") {
      in >> word >> word;
      EXPECT_EQ(word, "double");
      v.displacement.resize(v.points.size());
      for (auto& d : v.displacement) in >> d.x() >> d.y() >> d.z();
    } else if (word == "LOOKUP_TABLE" && !v.cells.empty() && v.region.empty()) {
      in >> word;
      v.region.resize(v.cells.size());
      for (int& r : v.region) in >> r;
    }
  }
  return v;
}

const std::string kScenes = std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/";

TEST(SolveCli, LiverOutputMatchesFullModelIncludingInteriorNodes) {
  const fs::path dir = scratch("tissue_solve_liver");
  fs::create_directories(dir);
  const std::string scene_file = kScenes + "liver.yaml";
  const SolveRun r = run_solve(scene_file + " --out " + (dir / "o.vtk").string() + " --stats " +
                               (dir / "o.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Vtk v = read_output(dir / "o.vtk");
  const Scene scene = load_scene(scene_file);
  ASSERT_EQ(v.points.size(), scene.mesh.nodes.size());
  ASSERT_EQ(v.cells.size(), scene.mesh.tets.size());
  for (size_t i = 0; i < v.points.size(); ++i)
    ASSERT_EQ(v.points[i], scene.mesh.nodes[i]);  // %.17g
  int operation = 0;
  for (int x : v.region) operation += x;
  EXPECT_GT(operation, 0);
  EXPECT_LT(operation, static_cast<int>(v.region.size()));
  // Every node, interior condensed ones included, equals the full model's solution.
  const FullModel full = assemble_full_model(scene);
  const Vector u = SparseCholesky(full.K).solve(full.f);
  double err = 0, ref = 0;
  for (int row = 0; row < full.dofs.rows(); ++row) {
    const int g = full.dofs.global_of[static_cast<size_t>(row)];
    err = std::max(err, std::abs(v.displacement[g / 3][g % 3] - u[row]));
    ref = std::max(ref, std::abs(u[row]));
  }
  std::printf("liver via tissue_solve: max |u| %.4e m, max error vs full model %.2e relative\n",
              ref, err / ref);
  EXPECT_LT(err / ref, 1e-9);

  std::ifstream js(dir / "o.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  for (const char* key :
       {"nodes", "tets", "dof_operation", "nodes_interface", "nodes_surface_condensed",
        "nodes_interior_condensed", "cuts", "tets_split", "volume_initial", "volume_final",
        "cg_iterations", "residual", "backend", "timings_ms", "nodes_smoothed", "flips"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["nodes"], scene.mesh.num_nodes());
  EXPECT_EQ(j["tets"], scene.mesh.num_tets());
  EXPECT_EQ(j["backend"], "cpu");
  EXPECT_EQ(j["cuts"], 0);
  EXPECT_GT(j["nodes_interface"].get<int>(), 0);
  EXPECT_LE(j["residual"].get<double>(), 1e-10);
  EXPECT_GT(j["cg_iterations"].get<int>(), 0);  // the equilibrium took iterations
}

TEST(SolveCli, ThighTrajectoryCutsAndKeepsVolume) {
  const fs::path dir = scratch("tissue_solve_thigh");
  fs::create_directories(dir);
  const SolveRun r = run_solve("thigh --out " + (dir / "o.vtk").string() + " --stats " +
                               (dir / "o.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream js(dir / "o.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  EXPECT_GT(j["cuts"].get<int>(), 0);
  EXPECT_GT(j["tets_split"].get<int>(), 0);
  EXPECT_NEAR(j["volume_final"].get<double>(), j["volume_initial"].get<double>(),
              1e-9 * j["volume_initial"].get<double>());
  // step_ms (docs/SCENE.md "Offline run"): the trajectory's steps by kind.
  ASSERT_TRUE(j.contains("step_ms"));
  int steps = 0;
  for (const char* kind : {"idle", "pressing", "cutting"}) {
    const nlohmann::json& k = j["step_ms"][kind];
    ASSERT_TRUE(k.contains("n") && k.contains("median") && k.contains("max")) << kind;
    steps += k["n"].get<int>();
    EXPECT_GE(k["median"].get<double>(), 0.0) << kind;
    EXPECT_GE(k["max"].get<double>(), k["median"].get<double>()) << kind;
    if (k["n"].get<int>() > 0) {
      EXPECT_GT(k["max"].get<double>(), 0.0) << kind;
    }
  }
  EXPECT_EQ(steps, static_cast<int>(load_scene("thigh").trajectory.size()));
  // Every cutting step inserted a cut, and a step may insert two (the end of one stroke and
  // the next one's first band).
  EXPECT_GT(j["step_ms"]["cutting"]["n"].get<int>(), 0);
  EXPECT_LE(j["step_ms"]["cutting"]["n"].get<int>(), j["cuts"].get<int>());
  EXPECT_GT(j["step_ms"]["pressing"]["n"].get<int>(), 0);
  const Vtk v = read_output(dir / "o.vtk");
  EXPECT_EQ(static_cast<int>(v.points.size()), j["nodes"].get<int>());
  EXPECT_EQ(static_cast<int>(v.cells.size()), j["tets"].get<int>());
  for (const Vec3& d : v.displacement) ASSERT_TRUE(d.allFinite());
  // Cells positively oriented (docs/SCENE.md "Offline run").
  for (const Tet& c : v.cells)
    ASSERT_GT((v.points[c[1]] - v.points[c[0]])
                  .dot((v.points[c[2]] - v.points[c[0]]).cross(v.points[c[3]] - v.points[c[0]])),
              0);
}

TEST(SolveCli, GlBackendAgreesWithCpu) {
  const fs::path dir = scratch("tissue_solve_gl");
  fs::create_directories(dir);
  const std::string scene_file = kScenes + "liver.yaml";
  ASSERT_EQ(run_solve(scene_file + " --backend cpu --out " + (dir / "cpu.vtk").string()).exit_code,
            0);
  const SolveRun r = run_solve(scene_file + " --backend gl --out " + (dir / "gl.vtk").string() +
                               " --stats " + (dir / "gl.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream js(dir / "gl.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  ASSERT_EQ(j["backend"], "gl") << r.err;  // llvmpipe through EGL in CI
  EXPECT_FALSE(j["renderer"].get<std::string>().empty());
  const Vtk a = read_output(dir / "cpu.vtk"), b = read_output(dir / "gl.vtk");
  double err = 0, ref = 0;
  for (size_t i = 0; i < a.displacement.size(); ++i) {
    err = std::max(err, (a.displacement[i] - b.displacement[i]).norm());
    ref = std::max(ref, a.displacement[i].norm());
  }
  EXPECT_LT(err / ref, 1e-5);
}

TEST(SolveCli, NonConvergedFinalSolveExits3AfterWritingOutputs) {
  // The liver on gl with max_iterations 3 cannot reach 1e-10 (Jacobi-scaled float CG): the
  // run must say so (exit 3, one line on stderr) after writing both outputs.
  const fs::path dir = scratch("tissue_solve_cap");
  fs::create_directories(dir);
  const fs::path scene = dir / "capped.yaml";
  const auto write_scene = [&](int max_iterations) {
    std::ofstream(scene)
        << "mesh: {file: " << kScenes << "../meshes/sofa_liver.msh, scale: 0.02}\n"
        << "material: {young_modulus: 3000.0, poisson_ratio: 0.3}\n"
        << "fixed: [{nodes: [2, 38, 63]}]\n"
        << "gravity: [0.0, -9.81, 0.0]\n"
        << "operation_region: {sphere: {center: [-0.039, 0.065, 0.0143], radius: 0.03}}\n"
        << "solver: {backend: gl, tolerance: 1.0e-10, max_iterations: " << max_iterations << "}\n";
  };
  write_scene(3);
  fs::remove(dir / "o.vtk");
  fs::remove(dir / "o.json");
  const SolveRun r = run_solve(scene.string() + " --out " + (dir / "o.vtk").string() + " --stats " +
                               (dir / "o.json").string());
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("did not converge"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("max_iterations (3)"), std::string::npos) << r.err;
  ASSERT_TRUE(fs::exists(dir / "o.vtk"));
  std::ifstream js(dir / "o.json");
  ASSERT_TRUE(js.good());
  const nlohmann::json j = nlohmann::json::parse(js);
  EXPECT_EQ(j["converged"], false);
  EXPECT_GT(j["residual"].get<double>(), 1e-10);
  EXPECT_EQ(j["backend"], "gl");  // llvmpipe through EGL; the cap is no reason to fall back
  EXPECT_EQ(j["backend_requested"], "gl");
  EXPECT_FALSE(j.contains("fallback_reason"));
  EXPECT_NE(j["solver_message"].get<std::string>().find("max_iterations"), std::string::npos);

  // With room to converge: exit 0, converged on gl, nothing on stderr.
  write_scene(2000);
  const SolveRun ok = run_solve(scene.string() + " --stats " + (dir / "o.json").string());
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(ok.err.empty()) << ok.err;
  std::ifstream js2(dir / "o.json");
  const nlohmann::json j2 = nlohmann::json::parse(js2);
  EXPECT_EQ(j2["converged"], true);
  EXPECT_EQ(j2["backend"], "gl");
  EXPECT_LE(j2["residual"].get<double>(), 1e-10);
}

TEST(SolveCli, BadInputIsOneLineNamingTheFile) {
  const fs::path dir = scratch("tissue_solve_bad");
  fs::create_directories(dir);
  const fs::path scene = dir / "bad.yaml";
  std::ofstream(scene) << "mesh: {generator: {type: thigh}}\nmaterial: {young_modulus: -5}\n";
  SolveRun r = run_solve(scene.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("young_modulus"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  r = run_solve((dir / "missing.yaml").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("missing.yaml"), std::string::npos) << r.err;
  r = run_solve(scene.string() + " --backend cuda");
  EXPECT_NE(r.exit_code, 0);
  r = run_solve("");
  EXPECT_NE(r.exit_code, 0);
}

}  // namespace
}  // namespace stc
