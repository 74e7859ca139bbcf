// A small condensation problem (the 4 cm test cube, bottom face fixed, gravity and a point
// load, an operation sphere at the top) and its dense reference blocks, assembled here over
// one DOF numbering of I u N from the element matrices: the reference the condensation and
// recovery tests compare with.
#pragma once

#include "common/meshes.hpp"
#include "soft_tissue_cutting/assembly/element_cache.hpp"
#include "soft_tissue_cutting/assembly/global_assembly.hpp"
#include "soft_tissue_cutting/assembly/loads.hpp"
#include "soft_tissue_cutting/partition/partition.hpp"

#include <Eigen/Dense>

#include <cstdint>
#include <vector>

namespace stc::test {

struct CondensationFixture {
  TetMesh mesh = cube_mesh();
  Material material;
  ElementStiffnessCache elements{mesh, material};
  Partition partition;
  std::vector<std::uint8_t> fixed;
  Vector loads;
  // Dense reference over the free DOFs of I (first) and N = S u Q, numbered like the
  // condensation's own maps (interface_dofs, condensed_dofs).
  Eigen::MatrixXd K_II, K_IN, K_NN;
  Vector f_I, f_N;

  CondensationFixture() {
    OperationRegion region;
    region.kind = OperationRegion::Kind::kSphere;
    region.sphere.center = Vec3(0.02, 0.02, 0.04);
    region.sphere.radius = 0.018;
    partition = partition_mesh(mesh, region);
    fixed.assign(static_cast<size_t>(mesh.num_nodes()), 0);
    for (int n = 0; n < mesh.num_nodes(); ++n)
      fixed[static_cast<size_t>(n)] = mesh.nodes[static_cast<size_t>(n)].z() < 1e-12;
    loads = gravity_loads(mesh, material.density, Vec3(0, 0, -9.81));
    for (int n : partition.surface) loads[3 * n + 1] += 1e-3;  // a sideways pull on S
  }

  // Fills the dense blocks for the given maps (rows of I and of N).
  void build_reference(const DofMap& i_map, const DofMap& n_map) {
    const int ni = i_map.rows(), nn = n_map.rows();
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(ni + nn, ni + nn);
    auto row = [&](int dof) {
      const int r = i_map.row_of[static_cast<size_t>(dof)];
      if (r >= 0) return r;
      const int s = n_map.row_of[static_cast<size_t>(dof)];
      return s >= 0 ? ni + s : -1;
    };
    // K^(2): the part-2 tets only (the operation part's stiffness never enters K0).
    for (int t : partition.condensed_tets) {
      const Tet& e = mesh.tets[static_cast<size_t>(t)];
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
              const int r = row(3 * e[a] + i), c = row(3 * e[b] + j);
              if (r >= 0 && c >= 0) k(r, c) += elements[t](3 * a + i, 3 * b + j);
            }
    }
    K_II = k.topLeftCorner(ni, ni);
    K_IN = k.topRightCorner(ni, nn);
    K_NN = k.bottomRightCorner(nn, nn);
    f_I = gather(loads, i_map);
    f_N = gather(loads, n_map);
  }
};

}  // namespace stc::test
