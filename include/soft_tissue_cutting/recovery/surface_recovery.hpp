// Recovering the condensed part from the interface displacements (docs/DESIGN.md section 5):
//   u_N = K2_NN^-1 (f_N - K2_NI u_I)      (N = S u Q: the visible surface S is its head)
// through the sparse factor of K2_NN kept by the condensation: one forward and one backward
// substitution, exact to rounding. The dense operator R = [K2_NN^-1 K2_NI]_S of the paper
// (u_S = c_S + R u_I) is not formed: it is 3|S| x 3|I| doubles (162 MB for a 55k-tet liver)
// and the hybrid model recovers only when u_I moved, at the rate the caller displays.
#pragma once

#include "soft_tissue_cutting/condensation/condensed_part.hpp"

#include <memory>

namespace stc {

// u_N (free DOFs of S u Q, in condensed.condensed_dofs order: S first) from the kept factor.
// stiffness_scale s: the part's stiffness is s times the factored one (set_young_modulus),
// so u_N = K2_NN^-1 (f_N / s - K2_NI u_I) with the unscaled K2.
Vector recover_condensed(const CondensedPart& condensed, const Vector& u_interface,
                         double stiffness_scale = 1.0);

// A whole-mesh displacement whose S and Q entries may still have to be recovered, holding
// everything that recovery needs: u copied, the condensed part shared (it is never changed
// once condensed, and stays alive when the model that made it is replaced). Taken under the
// caller's lock (HybridModel::displacement_snapshot), it can be recovered later on any thread
// without the model (the ROS display thread), and then gives the state at the time it was
// taken.
struct DisplacementSnapshot {
  Vector u;  // 3n: O and I as solved; S and Q as last recovered (from u's u_I unless stale)
  std::shared_ptr<const CondensedPart> condensed;
  double stiffness_scale = 1.0;  // by value: set_young_modulus rescales the model's
  bool stale = false;            // S and Q of u not recovered from u's own u_I yet

  // S and Q of u from its u_I (one sparse solve when stale, nothing otherwise). Thread-safe
  // for distinct snapshots: the shared factor is only read (SparseCholesky::solve).
  void recover();
};

}  // namespace stc
