// Recovering the condensed part from the interface displacements (docs/DESIGN.md section 5):
//   u_S = [K2_NN^-1 f_N]_S - [K2_NN^-1 K2_NI]_S u_I = c_S + R u_I     (every step, dense mat-vec)
//   u_N = K2_NN^-1 (f_N - K2_NI u_I)                                  (interior Q, output only)
#pragma once

#include "soft_tissue_cutting/condensation/condensed_part.hpp"

namespace stc {

struct SurfaceRecovery {
  DofMap surface_dofs;  // free DOFs of S
  Eigen::MatrixXd R;    // 3|S|_free x 3|I|_free
  Vector c_S;

  // u_S for the given free interface displacements.
  Vector recover(const Vector& u_interface) const;
};

// R and c_S are rows of X and K2_NN^-1 f_N already computed by the condensation (S is
// numbered first in its condensed_dofs).
SurfaceRecovery make_surface_recovery(const CondensedPart& condensed, int num_nodes,
                                      const std::vector<int>& surface_nodes,
                                      const std::vector<std::uint8_t>& fixed_node);

// u_N (free DOFs of S u Q, in condensed.condensed_dofs order) from the kept factor.
// stiffness_scale s: the part's stiffness is s times the factored one (set_young_modulus),
// so u_N = K2_NN^-1 (f_N / s - K2_NI u_I) with the unscaled K2.
Vector recover_condensed(const CondensedPart& condensed, const Vector& u_interface,
                         double stiffness_scale = 1.0);

}  // namespace stc
