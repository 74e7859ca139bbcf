#include "soft_tissue_cutting/generators/local_refinement.hpp"

#include <tetgen.h>

#include <stdexcept>

namespace stc {

TetMesh refine_region(const TetMesh& mesh, const OperationRegion& region, double max_volume) {
  tetgenio in, out;
  in.firstnumber = 0;
  in.numberofpoints = mesh.num_nodes();
  in.pointlist = new REAL[3 * static_cast<size_t>(mesh.num_nodes())];
  for (int i = 0; i < mesh.num_nodes(); ++i)
    for (int k = 0; k < 3; ++k) in.pointlist[3 * i + k] = mesh.nodes[i][k];
  in.numberoftetrahedra = mesh.num_tets();
  in.numberofcorners = 4;
  in.tetrahedronlist = new int[4 * static_cast<size_t>(mesh.num_tets())];
  in.tetrahedronvolumelist = new REAL[static_cast<size_t>(mesh.num_tets())];
  for (int t = 0; t < mesh.num_tets(); ++t) {
    Vec3 centroid = Vec3::Zero();
    for (int k = 0; k < 4; ++k) {
      in.tetrahedronlist[4 * t + k] = mesh.tets[t][k];
      centroid += mesh.nodes[mesh.tets[t][k]] / 4.0;
    }
    in.tetrahedronvolumelist[t] = region.contains(centroid) ? max_volume : -1.0;  // -1: free
  }
  // r: refine the given mesh; q1.5/18: radius-edge <= 1.5, dihedral >= 18 deg; a: the
  // per-tet volume limits above; O7: all local optimizations; Q: quiet.
  tetgenbehavior behavior;
  char switches[] = "rq1.5/18aO7Q";
  if (!behavior.parse_commandline(switches)) throw std::runtime_error("TetGen: bad switches");
  try {
    tetrahedralize(&behavior, &in, &out);
  } catch (...) {  // TetGen throws ints on failure
    throw std::runtime_error("TetGen could not refine the operation region");
  }
  TetMesh refined;
  refined.nodes.reserve(static_cast<size_t>(out.numberofpoints));
  for (int i = 0; i < out.numberofpoints; ++i)
    refined.nodes.emplace_back(out.pointlist[3 * i], out.pointlist[3 * i + 1],
                               out.pointlist[3 * i + 2]);
  refined.tets.reserve(static_cast<size_t>(out.numberoftetrahedra));
  for (int t = 0; t < out.numberoftetrahedra; ++t) {
    Tet tet = {out.tetrahedronlist[4 * t], out.tetrahedronlist[4 * t + 1],
               out.tetrahedronlist[4 * t + 2], out.tetrahedronlist[4 * t + 3]};
    if (tet_volume(TetMesh{refined.nodes, {tet}, {}}, 0) < 0) std::swap(tet[2], tet[3]);
    refined.tets.push_back(tet);
  }
  return refined;
}

}  // namespace stc
