// Helpers for the moving-operation-region tests: a long blade stroke played step by step, the
// area its edge sweeps inside the (rest) tissue, and the opened cut area.
#pragma once

#include "collision/tissue_samples.hpp"
#include "common/cut_measures.hpp"
#include "soft_tissue_cutting/assembly/element_cache.hpp"
#include "soft_tissue_cutting/assembly/full_model.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/cutting/invariants.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <algorithm>
#include <vector>

namespace stc::test {

// Poses from a to b (inclusive of b), `steps` equal steps, same orientation.
inline void append_line(std::vector<BladePose>& out, const Vec3& a, const Vec3& b, int steps,
                        const Eigen::Quaterniond& q) {
  for (int k = 1; k <= steps; ++k) {
    BladePose p;
    p.position = a + (b - a) * (static_cast<double>(k) / steps);
    p.orientation = q;
    p.t = out.empty() ? 0.0 : out.back().t + 0.01;
    out.push_back(p);
  }
}

// Area of the surface the blade edge sweeps between consecutive poses, inside the rest
// tissue `mesh`: each sweep quad (tip/heel at both poses) sampled n x n, a sample counted
// when a tet holds it. Independent of the cutter (a cut is only as good as this).
inline double swept_area_inside(const TetMesh& mesh, const std::vector<BladePose>& poses,
                                double blade_length, int n = 24) {
  TetGrid grid;
  grid.build(mesh, {});
  double area = 0;
  for (size_t i = 1; i < poses.size(); ++i) {
    const BladeEdge a = blade_edge(poses[i - 1], blade_length),
                    b = blade_edge(poses[i], blade_length);
    for (int u = 0; u < n; ++u)
      for (int v = 0; v < n; ++v) {
        const double s = (u + 0.5) / n, t = (v + 0.5) / n;
        // Bilinear patch x(s, t): s along the edge, t along the motion.
        const Vec3 ea = a.tip + s * (a.heel - a.tip), eb = b.tip + s * (b.heel - b.tip);
        const Vec3 x = (1 - t) * ea + t * eb;
        const Vec3 xs = (1 - t) * (a.heel - a.tip) + t * (b.heel - b.tip);
        const Vec3 xt = eb - ea;
        if (tet_containing(mesh, grid, x) >= 0) area += xs.cross(xt).norm() / (n * n);
      }
  }
  return area;
}

// max |u_sim - u_full| / max |u_full| over every DOF (interior condensed nodes recovered). The
// full model holds what the simulation holds: fixed nodes at zero, the nodes of free pieces
// held where they came free (HybridModel::held_nodes) at the simulation's displacement, so a
// cut-free piece (singular without them) is compared like the rest: K_ff u_f = f_f - K_fh u_h.
inline double relative_error_vs_full_model(Simulation& sim) {
  const Vector u = sim.full_displacement();
  const HybridModel& model = sim.model();
  const ElementStiffnessCache elements(model.mesh(), model.material());
  const FullModel full =
      assemble_full_model(model.mesh(), elements, model.loads(), model.fixed_nodes());
  const std::vector<std::uint8_t>& held = model.held_nodes();
  const int rows = full.dofs.rows();
  std::vector<int> free_row(static_cast<size_t>(rows), -1);
  std::vector<int> free_dofs;
  Vector u_held = Vector::Zero(rows);
  for (int r = 0; r < rows; ++r) {
    const int g = full.dofs.global_of[static_cast<size_t>(r)];
    const size_t node = static_cast<size_t>(g / 3);
    if (node < held.size() && held[node]) {
      u_held[r] = u[g];
    } else {
      free_row[static_cast<size_t>(r)] = static_cast<int>(free_dofs.size());
      free_dofs.push_back(r);
    }
  }
  const Vector rhs_all = full.f - full.K * u_held;
  std::vector<Eigen::Triplet<double>> t;
  for (int c = 0; c < full.K.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(full.K, c); it; ++it) {
      const int i = free_row[static_cast<size_t>(it.row())],
                j = free_row[static_cast<size_t>(it.col())];
      if (i >= 0 && j >= 0) t.emplace_back(i, j, it.value());
    }
  const auto nf = static_cast<Eigen::Index>(free_dofs.size());
  SparseMatrix k_ff(nf, nf);
  k_ff.setFromTriplets(t.begin(), t.end());
  Vector f_f(nf);
  for (Eigen::Index i = 0; i < nf; ++i) f_f[i] = rhs_all[free_dofs[static_cast<size_t>(i)]];
  const Vector x_f = SparseCholesky(k_ff).solve(f_f);
  Vector u_full = u_held;
  for (Eigen::Index i = 0; i < nf; ++i) u_full[free_dofs[static_cast<size_t>(i)]] = x_f[i];
  double err = 0, ref = 0;
  for (int r = 0; r < rows; ++r) {
    const int g = full.dofs.global_of[static_cast<size_t>(r)];
    err = std::max(err, std::abs(u[g] - u_full[r]));
    ref = std::max(ref, std::abs(u_full[r]));
  }
  return err / ref;
}

inline std::vector<std::string> spec6_violations(const Simulation& sim) {
  InvariantLimits limits;
  limits.initial_volume = sim.counts().volume_initial;
  return check_cut_invariants(sim.mesh(), sim.tet_size_classes(), limits);
}

}  // namespace stc::test
