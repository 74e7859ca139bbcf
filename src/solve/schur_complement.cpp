#include "soft_tissue_cutting/solve/schur_complement.hpp"

#include "solve/blas_guard.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace stc {
namespace {

// CHOLMOD's workspace, finished however the function leaves.
struct Common {
  cholmod_common c;
  Common() {
    cholmod_start(&c);
    c.print = 0;
  }
  ~Common() { cholmod_finish(&c); }
};

// The upper triangle of [A_AA A_AB; . A_BB + shift I] in CHOLMOD's compressed-column form
// (stype 1).
cholmod_sparse* upper_triangle_of_whole(const SparseMatrix& a_aa, const SparseMatrix& a_ab,
                                        const SparseMatrix& a_bb, double shift, cholmod_common* c) {
  const int na = static_cast<int>(a_aa.rows()), n = na + static_cast<int>(a_bb.rows());
  std::vector<std::vector<std::pair<int, double>>> column(static_cast<size_t>(n));
  for (int r = 0; r < a_aa.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(a_aa, r); it; ++it)
      if (it.col() >= r) column[static_cast<size_t>(it.col())].push_back({r, it.value()});
  for (int r = 0; r < a_ab.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(a_ab, r); it; ++it)
      column[static_cast<size_t>(na + it.col())].push_back({r, it.value()});
  for (int r = 0; r < a_bb.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(a_bb, r); it; ++it)
      if (it.col() > r) column[static_cast<size_t>(na + it.col())].push_back({na + r, it.value()});
  for (int j = 0; j < a_bb.rows(); ++j)  // the diagonal last in its column
    column[static_cast<size_t>(na + j)].push_back({na + j, a_bb.coeff(j, j) + shift});
  size_t nnz = 0;
  for (const auto& col : column) nnz += col.size();
  cholmod_sparse* m =
      cholmod_allocate_sparse(static_cast<size_t>(n), static_cast<size_t>(n), nnz,
                              /*sorted*/ 0, /*packed*/ 1, /*stype*/ 1, CHOLMOD_REAL, c);
  if (!m) throw std::runtime_error("schur_complement (CHOLMOD): out of memory");
  int* p = static_cast<int*>(m->p);
  int* i = static_cast<int*>(m->i);
  double* x = static_cast<double*>(m->x);
  size_t k = 0;
  for (int j = 0; j < n; ++j) {
    p[j] = static_cast<int>(k);
    for (const auto& [row, value] : column[static_cast<size_t>(j)]) i[k] = row, x[k++] = value;
  }
  p[n] = static_cast<int>(k);
  return m;
}

}  // namespace

Eigen::MatrixXd schur_complement(const SparseMatrix& a_aa, const SparseMatrix& a_ab,
                                 const SparseMatrix& a_bb) {
  const int na = static_cast<int>(a_aa.rows()), nb = static_cast<int>(a_bb.rows());
  if (a_aa.cols() != na || a_bb.cols() != nb || a_ab.rows() != na || a_ab.cols() != nb)
    throw std::invalid_argument("schur_complement: block sizes do not match");
  if (nb == 0) return Eigen::MatrixXd(0, 0);
  if (na == 0) return Eigen::MatrixXd(Eigen::MatrixXd(a_bb).selfadjointView<Eigen::Upper>());
  blas_info();  // before CHOLMOD's first call (solve/blas_guard.hpp)
  Common common;
  cholmod_common* c = &common.c;
  // A part whose A is held only through B (no fixed node: K^(2) of a condensed part that the
  // interface alone holds) makes the whole matrix singular though A_AA is SPD and S is only
  // semi-definite: B's block is shifted by its largest diagonal entry (the shifted matrix is
  // SPD: its Schur complement is S + shift I), and the shift is taken off S at the end - an
  // error of the order of the entries' own rounding.
  double shift = 0;
  for (int j = 0; j < nb; ++j) shift = std::max(shift, std::abs(a_bb.coeff(j, j)));
  if (!(shift > 0)) shift = 1;
  cholmod_sparse* m = upper_triangle_of_whole(a_aa, a_ab, a_bb, shift, c);
  const int n = na + nb;
  // B last, A ordered by CAMD for fill under that constraint.
  std::vector<int> member(static_cast<size_t>(n), 0), perm(static_cast<size_t>(n));
  std::fill(member.begin() + na, member.end(), 1);
  if (!cholmod_camd(m, nullptr, 0, member.data(), perm.data(), c)) {
    cholmod_free_sparse(&m, c);
    throw std::runtime_error("schur_complement (CHOLMOD): the CAMD ordering failed");
  }
  c->nmethods = 1;
  c->method[0].ordering = CHOLMOD_GIVEN;
  c->supernodal = CHOLMOD_SUPERNODAL;
  cholmod_factor* l = nullptr;
  // The elimination tree's postorder keeps B last when its columns form one chain to the root
  // (S dense, as for an interface); otherwise the given order is kept as it is.
  for (int postorder : {1, 0}) {
    c->postorder = postorder;
    l = cholmod_analyze_p(m, perm.data(), nullptr, 0, c);
    if (!l) break;
    const int* lp = static_cast<const int*>(l->Perm);
    bool b_last = true;
    for (int k = na; k < n && b_last; ++k) b_last = lp[k] >= na;
    if (b_last) break;
    cholmod_free_factor(&l, c);
  }
  if (!l) {
    cholmod_free_sparse(&m, c);
    throw std::runtime_error("schur_complement (CHOLMOD): the analysis failed");
  }
  bool ok;
  {
    const auto blas = blas_guard();
    ok = cholmod_factorize(m, l, c) && c->status == CHOLMOD_OK && l->minor == l->n;
  }
  cholmod_free_sparse(&m, c);
  if (!ok || !l->is_super) {
    cholmod_free_factor(&l, c);
    throw std::runtime_error(
        "schur_complement (CHOLMOD): matrix not positive definite - a part of the mesh is "
        "neither fixed nor held by the interface");
  }
  // L_BB, the trailing block of the supernodal L (rows and columns >= na in factor order).
  Eigen::MatrixXd l_bb = Eigen::MatrixXd::Zero(nb, nb);
  const int* super = static_cast<const int*>(l->super);
  const int* pi = static_cast<const int*>(l->pi);
  const int* px = static_cast<const int*>(l->px);
  const int* rows = static_cast<const int*>(l->s);
  const double* x = static_cast<const double*>(l->x);
  for (size_t s = 0; s < l->nsuper; ++s) {
    const int k1 = super[s], k2 = super[s + 1];
    if (k2 <= na) continue;
    const int nsrow = pi[s + 1] - pi[s];
    for (int k = std::max(k1, na); k < k2; ++k)
      for (int p = k - k1; p < nsrow; ++p) {  // the lower triangle of column k
        const int r = rows[pi[s] + p];
        if (r >= na) l_bb(r - na, k - na) = x[px[s] + static_cast<long>(k - k1) * nsrow + p];
      }
  }
  // S in factor order, then back in B's own order.
  Eigen::MatrixXd s_perm = Eigen::MatrixXd::Zero(nb, nb);
  s_perm.selfadjointView<Eigen::Lower>().rankUpdate(l_bb);
  s_perm = s_perm.selfadjointView<Eigen::Lower>();
  s_perm.diagonal().array() -= shift;
  const int* lp = static_cast<const int*>(l->Perm);
  std::vector<int> original(static_cast<size_t>(nb));
  for (int k = 0; k < nb; ++k) original[static_cast<size_t>(k)] = lp[na + k] - na;
  cholmod_free_factor(&l, c);
  Eigen::MatrixXd s(nb, nb);
  for (int j = 0; j < nb; ++j)
    for (int i = 0; i < nb; ++i)
      s(original[static_cast<size_t>(i)], original[static_cast<size_t>(j)]) = s_perm(i, j);
  return s;
}

}  // namespace stc
