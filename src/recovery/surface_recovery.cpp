#include "soft_tissue_cutting/recovery/surface_recovery.hpp"

namespace stc {

Vector recover_condensed(const CondensedPart& condensed, const Vector& u_interface,
                         double stiffness_scale) {
  Vector rhs = condensed.f_N / stiffness_scale;
  if (u_interface.size() > 0) rhs.noalias() -= condensed.K2_NI * u_interface;
  return condensed.factor_NN ? condensed.factor_NN->solve(rhs) : Vector(Vector::Zero(0));
}

}  // namespace stc
