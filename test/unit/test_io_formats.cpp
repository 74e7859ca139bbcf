// Every input format read correctly: each writer in test_io_util.hpp encodes the same box mesh,
// read_mesh must give it back exactly (node order = file order, tets positively oriented).
#include "test_io_util.hpp"

namespace stc {
namespace {

using test::TempDir;
using test::write_file;

void expect_same(const TetMesh& a, const TetMesh& b) {
  ASSERT_EQ(a.num_nodes(), b.num_nodes());
  ASSERT_EQ(a.num_tets(), b.num_tets());
  for (int i = 0; i < a.num_nodes(); ++i) EXPECT_EQ(a.nodes[i], b.nodes[i]) << "node " << i;
  for (int t = 0; t < a.num_tets(); ++t) EXPECT_EQ(a.tets[t], b.tets[t]) << "tet " << t;
}

void expect_positive(const TetMesh& m) {
  for (int t = 0; t < m.num_tets(); ++t) EXPECT_GT(tet_volume(m, t), 0) << "tet " << t;
}

struct FormatCase {
  const char* name;
  const char* file;
  std::string (*make)(const TetMesh&);
};

class ReadsEveryFormat : public ::testing::TestWithParam<FormatCase> {};

TEST_P(ReadsEveryFormat, GivesTheBoxBackExactly) {
  TempDir dir;
  const TetMesh box = test::small_box();
  const std::string path = write_file(dir.file(GetParam().file), GetParam().make(box));
  std::vector<std::string> warnings;
  const TetMesh mesh = read_mesh(path, {}, &warnings);
  expect_same(mesh, box);
  expect_positive(mesh);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
}

INSTANTIATE_TEST_SUITE_P(
    Formats, ReadsEveryFormat,
    ::testing::Values(
        FormatCase{"gmsh1", "a.msh", [](const TetMesh& m) { return test::gmsh_v1(m, 5); }},
        FormatCase{"gmsh22", "a.msh", [](const TetMesh& m) { return test::gmsh_v22(m, 3); }},
        FormatCase{"gmsh41", "a.msh", [](const TetMesh& m) { return test::gmsh_v41(m); }},
        FormatCase{"gmsh22bin", "a.msh", [](const TetMesh& m) { return test::gmsh_v22_binary(m); }},
        FormatCase{"gmsh41bin", "a.msh", [](const TetMesh& m) { return test::gmsh_v41_binary(m); }},
        FormatCase{"vtk_ascii", "a.vtk", [](const TetMesh& m) { return test::vtk_ascii(m); }},
        FormatCase{"vtk51_ascii", "a.VTK",
                   [](const TetMesh& m) { return test::vtk_ascii(m, true); }},
        FormatCase{"vtk_bin_double", "a.vtk",
                   [](const TetMesh& m) { return test::vtk_binary(m, false); }},
        FormatCase{"vtk_bin_float", "a.vtk",
                   [](const TetMesh& m) { return test::vtk_binary(m, true); }},
        FormatCase{"vtu", "a.vtu", [](const TetMesh& m) { return test::vtu_ascii(m); }}),
    [](const ::testing::TestParamInfo<FormatCase>& info) { return std::string(info.param.name); });

TEST(TetGenReader, OneBasedAndZeroBased) {
  const TetMesh box = test::small_box();
  for (int base : {0, 1}) {
    TempDir dir;
    const auto [node, ele] = test::tetgen_files(box, base);
    write_file(dir.file("m.node"), node);
    write_file(dir.file("m.ele"), ele);
    expect_same(read_mesh(dir.file("m.node")), box);
  }
}

TEST(TetGenReader, NegativeOrientationIsFlippedWithWarning) {
  TetMesh box = test::small_box();
  for (Tet& t : box.tets) std::swap(t[0], t[1]);
  TempDir dir;
  const auto [node, ele] = test::tetgen_files(box, 1);
  write_file(dir.file("m.node"), node);
  write_file(dir.file("m.ele"), ele);
  std::vector<std::string> warnings;
  const TetMesh mesh = read_mesh(dir.file("m.node"), {}, &warnings);
  expect_positive(mesh);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("flipped"), std::string::npos);
  EXPECT_NEAR(total_volume(mesh), 2.0, 1e-12);
}

TEST(MeshReader, UnreferencedNodesKeptWithWarning) {
  TetMesh box = test::small_box();
  box.nodes.push_back(Vec3(5, 5, 5));
  TempDir dir;
  const std::string path = write_file(dir.file("a.msh"), test::gmsh_v1(box));
  std::vector<std::string> warnings;
  const TetMesh mesh = read_mesh(path, {}, &warnings);
  EXPECT_EQ(mesh.num_nodes(), box.num_nodes());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("used by no tetrahedron"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find(path), std::string::npos);
}

// Closed surfaces go through TetGen: a closed, positively oriented volume of the box's size.
struct SurfaceCase {
  const char* name;
  const char* file;
  std::string (*make)(const TetMesh&);
};

class TetrahedralizesSurfaces : public ::testing::TestWithParam<SurfaceCase> {};

TEST_P(TetrahedralizesSurfaces, BoxVolume) {
  TempDir dir;
  const std::string path =
      write_file(dir.file(GetParam().file), GetParam().make(test::small_box()));
  std::vector<std::string> warnings;
  const TetMesh mesh = read_mesh(path, {}, &warnings);
  EXPECT_TRUE(warnings.empty());
  EXPECT_GE(mesh.num_nodes(), 12);
  expect_positive(mesh);
  EXPECT_NEAR(total_volume(mesh), 2.0, 1e-12);
  const BoundarySurface s = extract_boundary_surface(mesh);
  EXPECT_TRUE(is_closed_oriented_manifold(s));
  // The input vertices come first, in file order.
  EXPECT_EQ(mesh.nodes[0], test::small_box().nodes[0]);
}

INSTANTIATE_TEST_SUITE_P(Surfaces, TetrahedralizesSurfaces,
                         ::testing::Values(SurfaceCase{"obj", "s.obj", test::obj_surface},
                                           SurfaceCase{"off", "s.off", test::off_surface},
                                           SurfaceCase{"stl_ascii", "s.stl", test::stl_ascii},
                                           SurfaceCase{"stl_binary", "s.STL", test::stl_binary}),
                         [](const ::testing::TestParamInfo<SurfaceCase>& info) {
                           return std::string(info.param.name);
                         });

TEST(SurfaceReader, SofaLiver2Obj) {
  MeshReadOptions options;
  options.tetgen_switches = "pq1.4/10Q";  // coarser than the default for test speed
  const TetMesh mesh = read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/sofa_liver2.obj", options);
  EXPECT_GT(mesh.num_tets(), 1000);
  expect_positive(mesh);
  EXPECT_TRUE(is_closed_oriented_manifold(extract_boundary_surface(mesh)));
}

TEST(VtkWriter, RoundTripIsBitExact) {
  TempDir dir;
  TetMesh mesh = read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/sofa_liver.msh");
  for (Vec3& x : mesh.nodes) x /= 3.0;  // digits that need all 17
  Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(3 * mesh.num_nodes(), -1e-3, 1e-3);
  std::vector<std::uint8_t> region(static_cast<std::size_t>(mesh.num_tets()), 0);
  region[3] = 1;
  const std::string path = dir.file("out.vtk");
  write_vtk(path, mesh, u, region);
  expect_same(read_mesh(path), mesh);
  const std::string text = test::read_text(path);
  EXPECT_EQ(text.rfind("# vtk DataFile Version 3.0\n", 0), 0u);
  EXPECT_NE(text.find("\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 181 double\n"),
            std::string::npos);
  EXPECT_NE(text.find("\nCELLS 596 2980\n"), std::string::npos);
  EXPECT_NE(text.find("\nCELL_TYPES 596\n10\n"), std::string::npos);
  EXPECT_NE(text.find("\nPOINT_DATA 181\nVECTORS displacement double\n-0.001 "), std::string::npos);
  EXPECT_NE(
      text.find("\nCELL_DATA 596\nSCALARS region int 1\nLOOKUP_TABLE default\n0\n0\n0\n1\n0\n"),
      std::string::npos);
}

TEST(VtkWriter, RefusesBadSizesAndUnwritablePaths) {
  const TetMesh mesh = test::small_box();
  TempDir dir;
  EXPECT_THROW(write_vtk(dir.file("a.vtk"), mesh, Eigen::VectorXd::Zero(5), {}), MeshError);
  EXPECT_THROW(write_vtk(dir.file("a.vtk"), mesh, {}, std::vector<std::uint8_t>(3, 0)), MeshError);
  try {
    write_vtk(dir.file("no/such/dir/a.vtk"), mesh, {}, {});
    FAIL();
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("no/such/dir/a.vtk: cannot open"), std::string::npos);
  }
  write_vtk(dir.file("zeros.vtk"), mesh, {}, {});  // empty data = zeros
  expect_same(read_mesh(dir.file("zeros.vtk")), mesh);
}

}  // namespace
}  // namespace stc
