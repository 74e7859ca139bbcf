// Gmsh readers (formats 1, 2.2, 4.1; ASCII and binary) on the SOFA livers and generated files.
#include "test_io_util.hpp"

namespace stc {
namespace {

TEST(GmshReader, SofaLiverV1) {
  std::vector<std::string> warnings;
  const TetMesh mesh =
      read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/sofa_liver.msh", {}, &warnings);
  EXPECT_EQ(mesh.num_nodes(), 181);
  EXPECT_EQ(mesh.num_tets(), 596);
  EXPECT_EQ(mesh.nodes[0], Vec3(-0.979259, 2.23512, 2.61245));
  EXPECT_EQ(mesh.nodes[2], Vec3(-0.48104, 2.87797, 1.94243));
  // Element 1 is "4 128 141 138 142" (1-based tags): 0-based 127 140 137 141.
  EXPECT_EQ(mesh.tets[0], (Tet{127, 140, 137, 141}));
  for (int t = 0; t < mesh.num_tets(); ++t) EXPECT_GT(tet_volume(mesh, t), 0);
  EXPECT_TRUE(warnings.empty());
}

TEST(GmshReader, SofaLiver2V1IgnoresTrianglesAndLines) {
  const TetMesh mesh = read_mesh(std::string(TISSUE_SHARED_MESH_DIR) + "/sofa_liver2.msh");
  EXPECT_EQ(mesh.num_nodes(), 507);
  EXPECT_EQ(mesh.num_tets(), 1493);
  for (int t = 0; t < mesh.num_tets(); ++t) EXPECT_GT(tet_volume(mesh, t), 0);
}

}  // namespace
}  // namespace stc
