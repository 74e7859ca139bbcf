#include "soft_tissue_cutting/recovery/surface_recovery.hpp"

namespace stc {

Vector SurfaceRecovery::recover(const Vector& u_interface) const {
  if (R.cols() == 0) return c_S;
  Vector u = c_S;
  u.noalias() += R * u_interface;
  return u;
}

SurfaceRecovery make_surface_recovery(const CondensedPart& condensed, int num_nodes,
                                      const std::vector<int>& surface_nodes,
                                      const std::vector<std::uint8_t>& fixed_node) {
  SurfaceRecovery s;
  s.surface_dofs = make_dof_map(num_nodes, surface_nodes, fixed_node);
  const int ns = s.surface_dofs.rows();
  // condensed_dofs lists S first, so the surface rows are the top block.
  s.R = -condensed.solution_operator.topRows(ns);
  s.c_S = condensed.load_response.head(ns);
  return s;
}

Vector recover_condensed(const CondensedPart& condensed, const Vector& u_interface,
                         double stiffness_scale) {
  Vector rhs = condensed.f_N / stiffness_scale;
  if (u_interface.size() > 0) rhs.noalias() -= condensed.K2_NI * u_interface;
  return condensed.factor_NN ? condensed.factor_NN->solve(rhs) : Vector(Vector::Zero(0));
}

}  // namespace stc
