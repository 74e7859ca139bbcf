// Recovering the condensed part from the interface displacements (docs/DESIGN.md section 5):
//   u_N = K2_NN^-1 (f_N - K2_NI u_I)      (N = S u Q: the visible surface S is its head)
// through the sparse factor of K2_NN kept by the condensation: one forward and one backward
// substitution, exact to rounding. The dense operator R = [K2_NN^-1 K2_NI]_S of the paper
// (u_S = c_S + R u_I) is not formed: it is 3|S| x 3|I| doubles (162 MB for a 55k-tet liver)
// and the hybrid model recovers only when u_I moved, at the rate the caller displays.
#pragma once

#include "soft_tissue_cutting/condensation/condensed_part.hpp"

namespace stc {

// u_N (free DOFs of S u Q, in condensed.condensed_dofs order: S first) from the kept factor.
// stiffness_scale s: the part's stiffness is s times the factored one (set_young_modulus),
// so u_N = K2_NN^-1 (f_N / s - K2_NI u_I) with the unscaled K2.
Vector recover_condensed(const CondensedPart& condensed, const Vector& u_interface,
                         double stiffness_scale = 1.0);

}  // namespace stc
