// The full model and the hybrid model against CalculiX C3D4 (docs/DESIGN.md section 12): the test
// writes the .inp deck, runs `ccx -i job` in a temporary directory and parses job.dat.
// Pass: max nodal difference <= 1e-6 of the largest displacement (CalculiX prints 7 digits).
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/assembly/loads.hpp"
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include "liver_test_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace stc {
namespace {

bool have_ccx() { return std::system("command -v ccx > /dev/null 2>&1") == 0; }

// 1-based numbering, numbers as %.13e (at most 20 characters, or ccx refuses the line).
void write_deck(const std::string& path, const Scene& s) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fprintf(f, "*NODE, NSET=NALL\n");
  for (int i = 0; i < s.mesh.num_nodes(); ++i) {
    const Vec3& x = s.mesh.nodes[i];
    std::fprintf(f, "%d, %.13e, %.13e, %.13e\n", i + 1, x.x(), x.y(), x.z());
  }
  std::fprintf(f, "*ELEMENT, TYPE=C3D4, ELSET=EALL\n");
  for (int t = 0; t < s.mesh.num_tets(); ++t) {
    const Tet& e = s.mesh.tets[t];  // det[x1-x0, x2-x0, x3-x0] > 0, as C3D4 wants
    std::fprintf(f, "%d, %d, %d, %d, %d\n", t + 1, e[0] + 1, e[1] + 1, e[2] + 1, e[3] + 1);
  }
  const std::vector<std::uint8_t> fixed = fixed_node_mask(s);
  std::fprintf(f, "*NSET, NSET=FIX\n");
  int k = 0;
  for (int i = 0; i < s.mesh.num_nodes(); ++i)
    if (fixed[i]) std::fprintf(f, "%d,%s", i + 1, (++k % 12 == 0) ? "\n" : " ");
  std::fprintf(f, "\n*MATERIAL, NAME=TISSUE\n*ELASTIC\n%.13e, %.13e\n", s.material.young_modulus,
               s.material.poisson_ratio);
  const bool gravity = !s.gravity.isZero(0.0);
  if (gravity) std::fprintf(f, "*DENSITY\n%.13e\n", s.material.density);
  std::fprintf(f, "*SOLID SECTION, ELSET=EALL, MATERIAL=TISSUE\n*BOUNDARY\nFIX, 1, 3\n");
  std::fprintf(f, "*STEP\n*STATIC, SOLVER=SPOOLES\n");
  const Vector loads = point_loads(s);
  bool any = false;
  for (int i = 0; i < 3 * s.mesh.num_nodes(); ++i)
    if (loads[i] != 0) {
      if (!any) std::fprintf(f, "*CLOAD\n");
      any = true;
      std::fprintf(f, "%d, %d, %.13e\n", i / 3 + 1, i % 3 + 1, loads[i]);
    }
  if (gravity) {
    const double g = s.gravity.norm();
    const Vec3 d = s.gravity / g;
    std::fprintf(f, "*DLOAD\nEALL, GRAV, %.13e, %.13e, %.13e, %.13e\n", g, d.x(), d.y(), d.z());
  }
  std::fprintf(f, "*NODE PRINT, NSET=NALL\nU\n*END STEP\n");
  std::fclose(f);
}

// Runs ccx on the scene and returns the 3n displacement it prints.
Vector run_calculix(const Scene& s) {
  char dir_template[] = "/tmp/stc_ccx_XXXXXX";
  const char* dir = mkdtemp(dir_template);
  EXPECT_NE(dir, nullptr);
  if (!dir) return {};
  const std::string d(dir);
  write_deck(d + "/job.inp", s);
  const std::string cmd = "cd " + d + " && OMP_NUM_THREADS=1 ccx -i job > ccx.log 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << "ccx failed, see " << d << "/ccx.log";
  std::ifstream in(d + "/job.dat");
  Vector u = Vector::Constant(3 * s.mesh.num_nodes(), std::nan(""));
  std::string line;
  bool in_block = false;
  int read = 0;
  while (std::getline(in, line)) {
    if (line.find("displacements (vx,vy,vz) for set NALL") != std::string::npos) {
      in_block = true;
      continue;
    }
    if (!in_block) continue;
    std::istringstream ls(line);
    int node;
    double x, y, z;
    if (ls >> node >> x >> y >> z) {
      u.segment<3>(3 * (node - 1)) = Vec3(x, y, z);
      ++read;
    } else if (read > 0) {
      break;
    }
  }
  EXPECT_EQ(read, s.mesh.num_nodes());
  if (!::testing::Test::HasFailure()) std::system(("rm -rf " + d).c_str());
  return u;
}

Vector solve_full(const Scene& s) {
  const FullModel m = assemble_full_model(s);
  Vector x;
  solve_direct(m.K, m.f, x);
  Vector u = Vector::Zero(3 * s.mesh.num_nodes());
  scatter(x, m.dofs, u);
  return u;
}

double max_nodal_difference(const Vector& u, const Vector& ref) {
  double scale = 0, err = 0;
  for (Eigen::Index n = 0; n < ref.size() / 3; ++n) {
    scale = std::max(scale, ref.segment<3>(3 * n).norm());
    err = std::max(err, (u.segment<3>(3 * n) - ref.segment<3>(3 * n)).norm());
  }
  return err / scale;
}

// Full and hybrid model vs CalculiX.
void check_against_calculix(const Scene& s, const char* name) {
  if (!have_ccx()) GTEST_SKIP() << "ccx (calculix-ccx) not installed";
  const Vector ccx = run_calculix(s);
  ASSERT_FALSE(ccx.hasNaN());
  const Vector full = solve_full(s);
  HybridModel h(s);
  h.set_cg_settings(CgSettings{1e-11, 20000});  // the slender beam stalls near 1e-12
  const CgResult r = h.solve();
  EXPECT_TRUE(r.converged) << r.iterations << " iterations, residual " << r.residual;
  h.recover_interior();
  const double e_full = max_nodal_difference(full, ccx);
  const double e_hybrid = max_nodal_difference(h.displacement(), ccx);
  EXPECT_LE(e_full, 1e-6);
  EXPECT_LE(e_hybrid, 1e-6);
  double umax = 0;
  for (Eigen::Index n = 0; n < ccx.size() / 3; ++n)
    umax = std::max(umax, ccx.segment<3>(3 * n).norm());
  std::printf("[ calculix ] %-22s %5d nodes %6d tets |u|max %.4e m: full %.2e, hybrid %.2e\n", name,
              s.mesh.num_nodes(), s.mesh.num_tets(), umax, e_full, e_hybrid);
}

// The cantilever of docs/DESIGN.md section 12: 0.1 x 0.02 x 0.02 m, E = 1e4, nu = 0.3, x = 0 fixed,
// tip force 1e-4 N (-z) spread over the x = L face by tributary area.
Scene cantilever_scene(std::array<int, 3> cells) {
  Scene s;
  s.source = "cantilever";
  GeneratorParams g;
  g.type = "box";
  g.size = Vec3(0.1, 0.02, 0.02);
  g.cells = cells;
  s.mesh = make_box_mesh(g);
  s.material = Material{1e4, 0.3, 1000.0};
  NodeSelector root;
  root.kind = NodeSelector::Kind::kBox;
  root.box = Box{Vec3(-1e-9, -1, -1), Vec3(1e-9, 1, 1)};
  s.fixed.push_back(root);
  const double hy = g.size.y() / cells[1], hz = g.size.z() / cells[2];
  for (int n = 0; n < s.mesh.num_nodes(); ++n) {
    const Vec3& x = s.mesh.nodes[n];
    if (x.x() < g.size.x() - 1e-9) continue;
    const bool edge_y = x.y() < 1e-9 || x.y() > g.size.y() - 1e-9;
    const bool edge_z = x.z() < 1e-9 || x.z() > g.size.z() - 1e-9;
    const double area = (edge_y ? 0.5 : 1.0) * hy * (edge_z ? 0.5 : 1.0) * hz;
    Load l;
    l.where.nodes = {n};
    l.force = Vec3(0, 0, -1e-4 * area / (g.size.y() * g.size.z()));
    s.loads.push_back(l);
  }
  s.operation_region.kind = OperationRegion::Kind::kBox;  // near the tip
  s.operation_region.box = Box{Vec3(0.07, -1, -1), Vec3(0.2, 1, 1)};
  return s;
}

TEST(CalculixReference, Cantilever20x4x4) {
  const Scene s = cantilever_scene({20, 4, 4});
  check_against_calculix(s, "cantilever 20x4x4");
  // Beam theory as a convergence sanity check (linear tets are stiff): tip deflection
  // between 0.7 and 1.0 of Euler-Bernoulli's 2.5e-4 m.
  const Vector u = solve_full(s);
  double tip = 0;
  int count = 0;
  for (int n = 0; n < s.mesh.num_nodes(); ++n)
    if (s.mesh.nodes[n].x() > 0.1 - 1e-9) tip += u[3 * n + 2], ++count;
  tip /= count;
  std::printf("[ calculix ] cantilever 20x4x4 mean tip deflection %.4e m (EB 2.500e-4)\n", -tip);
  EXPECT_GT(-tip, 0.7 * 2.5e-4);
  EXPECT_LT(-tip, 1.0 * 2.5e-4);
}

TEST(CalculixReference, CantileverGravity) {
  Scene s = cantilever_scene({20, 4, 4});
  s.gravity = Vec3(0, 0, -9.81);
  s.loads.clear();
  check_against_calculix(s, "cantilever gravity");
}

TEST(CalculixReference, Thigh) { check_against_calculix(make_thigh_scene(), "thigh"); }

TEST(CalculixReference, ThighGravity) {
  Scene s = make_thigh_scene();
  s.gravity = Vec3(0, -9.81, 0);
  check_against_calculix(s, "thigh + gravity");
}

// The SOFA livers: a 3-node load near the top, an operation sphere around it.
Scene liver_scene(const std::string& file, bool gravity) {
  return testing_scenes::liver_scene(file, gravity, 3, 0.25);
}

TEST(CalculixReference, SofaLiver) {
  check_against_calculix(liver_scene("sofa_liver.msh", false), "sofa_liver");
}
TEST(CalculixReference, SofaLiverGravity) {
  check_against_calculix(liver_scene("sofa_liver.msh", true), "sofa_liver + gravity");
}
TEST(CalculixReference, SofaLiver2) {
  check_against_calculix(liver_scene("sofa_liver2.msh", false), "sofa_liver2");
}
TEST(CalculixReference, SofaLiver2Gravity) {
  check_against_calculix(liver_scene("sofa_liver2.msh", true), "sofa_liver2 + gravity");
}

}  // namespace
}  // namespace stc
