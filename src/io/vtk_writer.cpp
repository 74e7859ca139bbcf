// The output file of docs/SCENE.md "Offline run": VTK legacy ASCII UNSTRUCTURED_GRID with rest
// positions, tets (type 10), the displacement of every node and the operation-region flag of every
// tet.
#include "soft_tissue_cutting/io/vtk_writer.hpp"

#include <cstdio>
#include <memory>

namespace stc {

void write_vtk(const std::string& path, const TetMesh& mesh, const Eigen::VectorXd& displacement,
               const std::vector<std::uint8_t>& tet_region) {
  const long n = mesh.num_nodes(), m = mesh.num_tets();
  if (displacement.size() != 0 && displacement.size() != 3 * n)
    throw MeshError(path + ": displacement has " + std::to_string(displacement.size()) +
                    " entries, expected 3 x " + std::to_string(n) + " nodes");
  if (!tet_region.empty() && static_cast<long>(tet_region.size()) != m)
    throw MeshError(path + ": tet_region has " + std::to_string(tet_region.size()) +
                    " entries, expected " + std::to_string(m) + " tets");
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "w"), &std::fclose);
  if (!file) throw MeshError(path + ": cannot open for writing");
  FILE* f = file.get();
  std::fprintf(f, "# vtk DataFile Version 3.0\nsoft_tissue_cutting\nASCII\n");
  std::fprintf(f, "DATASET UNSTRUCTURED_GRID\nPOINTS %ld double\n", n);
  for (const Vec3& x : mesh.nodes) std::fprintf(f, "%.17g %.17g %.17g\n", x.x(), x.y(), x.z());
  std::fprintf(f, "CELLS %ld %ld\n", m, 5 * m);
  for (const Tet& t : mesh.tets) std::fprintf(f, "4 %d %d %d %d\n", t[0], t[1], t[2], t[3]);
  std::fprintf(f, "CELL_TYPES %ld\n", m);
  for (long t = 0; t < m; ++t) std::fputs("10\n", f);
  std::fprintf(f, "POINT_DATA %ld\nVECTORS displacement double\n", n);
  for (long i = 0; i < n; ++i) {
    if (displacement.size() == 0) {
      std::fputs("0 0 0\n", f);
    } else {
      std::fprintf(f, "%.17g %.17g %.17g\n", displacement[3 * i], displacement[3 * i + 1],
                   displacement[3 * i + 2]);
    }
  }
  std::fprintf(f, "CELL_DATA %ld\nSCALARS region int 1\nLOOKUP_TABLE default\n", m);
  for (long t = 0; t < m; ++t)
    std::fprintf(f, "%d\n",
                 tet_region.empty() ? 0 : (tet_region[static_cast<std::size_t>(t)] ? 1 : 0));
  const bool write_failed = std::ferror(f) != 0;
  if (std::fclose(file.release()) != 0 || write_failed)
    throw MeshError(path + ": write failed (disk full or I/O error)");
}

}  // namespace stc
