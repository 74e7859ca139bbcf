#include "soft_tissue_cutting/recovery/surface_recovery.hpp"

namespace stc {

Vector recover_condensed(const CondensedPart& condensed, const Vector& u_interface,
                         double stiffness_scale) {
  Vector rhs = condensed.f_N / stiffness_scale;
  if (u_interface.size() > 0) rhs.noalias() -= condensed.K2_NI * u_interface;
  return condensed.factor_NN ? condensed.factor_NN->solve(rhs) : Vector(Vector::Zero(0));
}

void DisplacementSnapshot::recover() {
  if (!stale) return;
  if (condensed && condensed->condensed_dofs.rows() > 0)
    scatter(recover_condensed(*condensed, gather(u, condensed->interface_dofs), stiffness_scale),
            condensed->condensed_dofs, u);
  stale = false;
}

}  // namespace stc
