#include "soft_tissue_cutting/solve/framed_cholesky.hpp"

#include "solve/blas_guard.hpp"
#include "solve/interface_last_order.hpp"
#include "solve/upper_triangle.hpp"

#include <Eigen/Cholesky>
#include <Eigen/CholmodSupport>

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <string>

// LAPACK and BLAS (OpenBLAS through Debian's alternatives, as CHOLMOD's): the frame's dense
// Schur complement is factored and applied at BLAS speed, not Eigen's portable kernels.
extern "C" {
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
void dpotrs_(const char* uplo, const int* n, const int* nrhs, const double* a, const int* lda,
             double* b, const int* ldb, int* info);
void dtrmm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m,
            const int* n, const double* alpha, const double* a, const int* lda, double* b,
            const int* ldb);
void dtrmv_(const char* uplo, const char* trans, const char* diag, const int* n, const double* a,
            const int* lda, double* x, const int* incx);
void dtrsv_(const char* uplo, const char* trans, const char* diag, const int* n, const double* a,
            const int* lda, double* x, const int* incx);
void dlauum_(const char* uplo, const int* n, double* a, const int* lda, int* info);
}

namespace stc {
namespace {

// B = op(L) B with L lower triangular (n x n, column-major), B n x m. One column goes through
// the level-2 routine: OpenBLAS's level-3 one packs all of L first (3x slower for m = 1).
void lower_times(const Eigen::MatrixXd& l, bool transpose, Eigen::MatrixXd& b) {
  const int n = static_cast<int>(l.rows()), m = static_cast<int>(b.cols()), one_step = 1;
  if (n == 0 || m == 0) return;
  const double one = 1.0;
  if (m == 1)
    dtrmv_("L", transpose ? "T" : "N", "N", &n, l.data(), &n, b.data(), &one_step);
  else
    dtrmm_("L", "L", transpose ? "T" : "N", "N", &n, &m, &one, l.data(), &n, b.data(), &n);
}

// B = (L L^T)^-1 B for the Cholesky factor L (lower, n x n), B n x m.
void cholesky_solve(const Eigen::MatrixXd& l, Eigen::MatrixXd& b) {
  const int n = static_cast<int>(l.rows()), m = static_cast<int>(b.cols()), one_step = 1;
  if (n == 0 || m == 0) return;
  if (m == 1) {
    dtrsv_("L", "N", "N", &n, l.data(), &n, b.data(), &one_step);
    dtrsv_("L", "T", "N", &n, l.data(), &n, b.data(), &one_step);
    return;
  }
  int info = 0;
  dpotrs_("L", &n, &m, l.data(), &n, b.data(), &n, &info);
}

bool same_row(const SparseMatrix& a, const SparseMatrix& b, int r) {
  const int na = a.outerIndexPtr()[r + 1] - a.outerIndexPtr()[r];
  const int nb = b.outerIndexPtr()[r + 1] - b.outerIndexPtr()[r];
  if (na != nb) return false;
  const int* ia = a.innerIndexPtr() + a.outerIndexPtr()[r];
  const int* ib = b.innerIndexPtr() + b.outerIndexPtr()[r];
  const double* va = a.valuePtr() + a.outerIndexPtr()[r];
  const double* vb = b.valuePtr() + b.outerIndexPtr()[r];
  return std::equal(ia, ia + na, ib) && std::equal(va, va + na, vb);
}

}  // namespace

// The frame's extra rows X and what eqs. (28)-(29) need of them (n_f: the rows of F).
struct Extra {
  std::vector<int> rows;       // X, in the order of S's trailing block
  std::vector<int> positions;  // their places in the elimination order (< n_f)
  Eigen::MatrixXd y;           // Y = L_FF^-1 E_X                        (n_f x |X|)
  Eigen::MatrixXd m;           // M = L_FF^-1 A_FX                       (n_f x |X|)
  Eigen::MatrixXd q;           // Q = L_BF Y                             (|B| x |X|)
  Eigen::MatrixXd t;           // T_XX = (Y^T Y)^-1                      (|X| x |X|)
  Eigen::MatrixXd w;           // W'' over [B, X] (eq. (28)), lower triangle
  bool empty() const { return rows.empty(); }
};

struct FramedCholesky::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  SparseMatrix factored;       // the matrix L L^T is of: its F rows are the reference
  std::vector<int> perm;       // elimination order: perm[k] is the row eliminated k-th
  int n_f = 0;                 // rows of F (perm[0, n_f)); the old frame is perm[n_f, n)
  std::vector<char> in_frame;  // per factored row: in the frame (its extra rows too)
  Eigen::MatrixXd l_bb;        // L's trailing frame block (lower, column-major)
  Eigen::MatrixXd w;           // W = A_BB - L_BB L_BB^T, eq. (26) (lower triangle used)
  Eigen::MatrixXd schur;       // the Cholesky factor of S' (lower), once update() took a matrix
  bool updated = false;
  std::vector<int> position;  // inverse of perm: where row r is eliminated

  // Rows of F that later changes moved into the frame, X (eq. (28)); F' = F \ X.
  Extra extra;

  Impl() {
    cholmod_start(&common);
    common.print = 0;
  }

  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }

  // x = L^-1 b (sys CHOLMOD_L) or L^-T b (CHOLMOD_Lt), no permutation; b is n x m.
  Eigen::MatrixXd triangular_solve(int sys, const Eigen::MatrixXd& b) const {
    cholmod_common c;
    cholmod_start(&c);
    c.print = 0;
    cholmod_dense rhs{};
    rhs.nrow = rhs.d = static_cast<size_t>(b.rows());
    rhs.ncol = static_cast<size_t>(b.cols());
    rhs.nzmax = rhs.nrow * rhs.ncol;
    rhs.x = const_cast<double*>(b.data());  // read only
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* x = nullptr;
    {
      const auto blas = blas_guard();
      x = cholmod_solve(sys, factor, &rhs, &c);
    }
    if (!x) {
      cholmod_finish(&c);
      throw std::runtime_error("framed Cholesky (CHOLMOD): the solve failed (out of memory?)");
    }
    Eigen::MatrixXd out =
        Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), b.rows(), b.cols());
    cholmod_free_dense(&x, &c);
    cholmod_finish(&c);
    return out;
  }

  // Visits L's stored lower part in columns [first, last), row by row within each supernode:
  // f(row, c0, c1, v, stride) with L(row, c) = v[(c - c0) * stride] for c0 <= c < c1 <= row + 1.
  // (Supernode s is a column-major block: its rows are Ls[pi[s] .. pi[s+1]), its columns
  // super[s] .. super[s+1].)
  template <typename RowSegment>
  void for_each_l_row_segment(int first, int last, RowSegment f) const {
    const auto* super = static_cast<const int*>(factor->super);
    const auto* pi = static_cast<const int*>(factor->pi);
    const auto* px = static_cast<const int*>(factor->px);
    const auto* ls = static_cast<const int*>(factor->s);
    const auto* lx = static_cast<const double*>(factor->x);
    for (size_t sn = 0; sn < factor->nsuper && super[sn] < last; ++sn) {
      if (super[sn + 1] <= first) continue;
      const int nrows = pi[sn + 1] - pi[sn];
      const int c0 = std::max(super[sn], first), c1 = std::min(super[sn + 1], last);
      for (int ii = 0; ii < nrows; ++ii) {
        const int row = ls[pi[sn] + ii], end = std::min(c1, row + 1);
        if (end > c0)
          f(row, c0, end, lx + px[sn] + static_cast<ptrdiff_t>(c0 - super[sn]) * nrows + ii, nrows);
      }
    }
  }

  // Rows `positions` (< n_f) of L_FF, transposed: n_f x |positions|. They are M = L_FF^-1 A_FX
  // for those rows X (A_FX = A_FF E_X = L_FF L_FF^T E_X), read from the factor instead of
  // solved for.
  Eigen::MatrixXd l_rows_transposed(const std::vector<int>& positions) const {
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n_f, static_cast<Eigen::Index>(positions.size()));
    std::vector<int> column_of(position.size(), -1);
    for (size_t j = 0; j < positions.size(); ++j)
      column_of[static_cast<size_t>(positions[j])] = static_cast<int>(j);
    for_each_l_row_segment(0, n_f, [&](int row, int c0, int c1, const double* v, int stride) {
      const int j = column_of[static_cast<size_t>(row)];
      for (int c = c0; j >= 0 && c < c1; ++c)
        out(c, j) = v[static_cast<ptrdiff_t>(c - c0) * stride];
    });
    return out;
  }

  // `from` with the rows `added` of F moved into the frame as well (eq. (28)): their columns
  // of Y and Q by one forward solve of |added| columns, of M from L's rows, then T_XX and W''
  // anew (dense, |X| small). Rows of A are the factored matrix's.
  std::optional<Extra> extended(const Extra& from, const std::vector<int>& added) const {
    const int n_old = static_cast<int>(factored.rows()), nb = n_old - n_f;
    const int k = static_cast<int>(added.size()), k0 = static_cast<int>(from.rows.size());
    Extra x;  // T and W'' are made anew below: from's are not copied
    x.rows = from.rows;
    x.rows.insert(x.rows.end(), added.begin(), added.end());
    x.positions = from.positions;
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n_old, k);
    std::vector<int> added_positions;
    for (int j = 0; j < k; ++j) {
      const int p = position[static_cast<size_t>(added[static_cast<size_t>(j)])];
      x.positions.push_back(p);
      added_positions.push_back(p);
      rhs(p, j) = 1.0;
    }
    const Eigen::MatrixXd l = triangular_solve(CHOLMOD_L, rhs);
    // L^-1 [E_X; 0] = [Y; -L_BB^-1 L_BF Y], so Q = L_BF Y = -L_BB times its frame rows.
    Eigen::MatrixXd q = -l.bottomLeftCorner(nb, k);
    {
      const auto blas = blas_guard();
      lower_times(l_bb, false, q);
    }
    auto joined = [](const Eigen::MatrixXd& left, const Eigen::MatrixXd& cols) {
      Eigen::MatrixXd out(cols.rows(), left.cols() + cols.cols());
      if (left.cols() > 0) out.leftCols(left.cols()) = left;
      out.rightCols(cols.cols()) = cols;
      return out;
    };
    x.y = joined(from.y, l.topLeftCorner(n_f, k));
    x.m = joined(from.m, l_rows_transposed(added_positions));
    x.q = joined(from.q, q);
    const int nx = k0 + k;
    Eigen::MatrixXd a_xb = Eigen::MatrixXd::Zero(nx, nb);  // of the factored matrix
    Eigen::MatrixXd a_xx = Eigen::MatrixXd::Zero(nx, nx);
    std::vector<int> in_x(static_cast<size_t>(n_old), -1);
    for (int j = 0; j < nx; ++j) in_x[static_cast<size_t>(x.rows[static_cast<size_t>(j)])] = j;
    for (int j = 0; j < nx; ++j)
      for (SparseMatrix::InnerIterator it(factored, x.rows[static_cast<size_t>(j)]); it; ++it) {
        const int c = static_cast<int>(it.index());
        if (const int p = position[static_cast<size_t>(c)]; p >= n_f) a_xb(j, p - n_f) = it.value();
        if (const int i = in_x[static_cast<size_t>(c)]; i >= 0) a_xx(j, i) = it.value();
      }
    // T_XX = (Y^T Y)^-1 = ((A_FF^-1)_XX)^-1, the Schur complement of A_F'F' onto X.
    const Eigen::LLT<Eigen::MatrixXd> g(x.y.transpose() * x.y);
    if (g.info() != Eigen::Success) return std::nullopt;
    x.t = g.solve(Eigen::MatrixXd::Identity(nx, nx));
    // W'' over [B, X]: W - Q T Q^T, A_XX - T, A_XB - T Q^T (lower triangle).
    const Eigen::MatrixXd tq = x.t * x.q.transpose();  // |X| x |B|
    x.w.resize(nb + nx, nb + nx);
    x.w.topLeftCorner(nb, nb) = w.selfadjointView<Eigen::Lower>();
    x.w.topLeftCorner(nb, nb).noalias() -= x.q * tq;
    x.w.bottomRightCorner(nx, nx) = a_xx - x.t;
    x.w.bottomLeftCorner(nx, nb) = a_xb - tq;
    return x;
  }
};

FramedCholesky::FramedCholesky(SparseMatrix matrix, std::vector<int> frame)
    : impl_(std::make_unique<Impl>()), rows_(static_cast<int>(matrix.rows())) {
  blas_info();  // before CHOLMOD's first call (solve/blas_guard.hpp)
  Impl& m = *impl_;
  const int n = rows_;
  m.factored = std::move(matrix);
  const SparseMatrix& a = m.factored;
  m.in_frame.assign(static_cast<size_t>(n), 0);
  std::sort(frame.begin(), frame.end());
  frame.erase(std::unique(frame.begin(), frame.end()), frame.end());
  for (int r : frame) {
    if (r < 0 || r >= n) throw std::invalid_argument("FramedCholesky: frame row out of range");
    m.in_frame[static_cast<size_t>(r)] = 1;
  }
  if (n == 0) return;

  Eigen::SparseMatrix<double, Eigen::ColMajor, int> upper = upper_triangle(a);
  cholmod_sparse view = Eigen::viewAsCholmod(upper);
  view.stype = 1;  // the upper triangle of a symmetric matrix
  // Every F row before every frame row (set 0 before set 1), each set in constrained AMD
  // order with its dense rows last, as AMD orders them (the interface block's: the ordering
  // and the analysis skip their block, solve/interface_last_order.hpp). CHOLMOD then analyses
  // that order as given and does not postorder it: a postorder may move F columns behind
  // frame columns.
  const std::vector<char> dense = dense_rows(a);
  m.perm = order_dense_last(upper, dense, m.in_frame, m.common);
  ColMatrix star;
  cholmod_sparse pattern = view;
  if (const auto hub = std::find_if(m.perm.begin(), m.perm.end(),
                                    [&](int r) { return dense[static_cast<size_t>(r)] != 0; });
      hub != m.perm.end()) {
    star = dense_star_pattern(upper, dense, *hub);
    pattern = Eigen::viewAsCholmod(star);
    pattern.stype = 1;
  }
  m.common.nmethods = 1;
  m.common.method[0].ordering = CHOLMOD_GIVEN;
  m.common.postorder = false;
  m.common.supernodal = CHOLMOD_SUPERNODAL;
  m.factor = cholmod_analyze_p(&pattern, m.perm.data(), nullptr, 0, &m.common);
  if (!m.factor) throw std::runtime_error("framed Cholesky (CHOLMOD): the analysis failed");
  factor_flops_ = m.common.fl;
  {
    const auto blas = blas_guard();
    cholmod_factorize(&view, m.factor, &m.common);
  }
  if (m.common.status == CHOLMOD_NOT_POSDEF || m.factor->minor < m.factor->n)
    throw std::runtime_error(
        "framed Cholesky (CHOLMOD): matrix not positive definite - a part of the mesh is "
        "neither fixed nor held by the interface");
  const int* p = static_cast<const int*>(m.factor->Perm);
  if (!std::equal(m.perm.begin(), m.perm.end(), p))
    throw std::logic_error("framed Cholesky: CHOLMOD did not keep the given order");
  m.n_f = n - static_cast<int>(frame.size());
  frame_.assign(m.perm.begin() + m.n_f, m.perm.end());
  m.position.assign(static_cast<size_t>(n), 0);
  for (int k = 0; k < n; ++k) m.position[static_cast<size_t>(m.perm[static_cast<size_t>(k)])] = k;

  // L_BB, the factor's trailing frame block.
  const int nb = static_cast<int>(frame_.size());
  m.l_bb = Eigen::MatrixXd::Zero(nb, nb);
  m.for_each_l_row_segment(m.n_f, n, [&](int row, int c0, int c1, const double* v, int stride) {
    for (int c = c0; c < c1; ++c)
      m.l_bb(row - m.n_f, c - m.n_f) = v[static_cast<ptrdiff_t>(c - c0) * stride];
  });
  // W = A_BB - L_BB L_BB^T (eq. (26)): what F adds to the frame's Schur complement.
  std::vector<int> pos(static_cast<size_t>(n), -1);
  for (int j = 0; j < nb; ++j) pos[static_cast<size_t>(frame_[static_cast<size_t>(j)])] = j;
  m.w = Eigen::MatrixXd::Zero(nb, nb);
  for (int j = 0; j < nb; ++j)
    for (SparseMatrix::InnerIterator it(a, frame_[static_cast<size_t>(j)]); it; ++it)
      if (const int i = pos[static_cast<size_t>(it.index())]; i >= 0) m.w(i, j) = it.value();
  // L_BB L_BB^T by LAPACK's dlauum, which forms U U^T of an upper triangle U: with J the
  // reversal, J L J is upper and L L^T = J (J L J)(J L J)^T J. A third of the flops of the
  // general product (dsyrk, which does not know L_BB is triangular): the organ liver's frames of
  // ~450 DOFs, ~2.5 -> ~1 ms a refactorization.
  if (nb > 0) {
    Eigen::MatrixXd u = m.l_bb.reverse();
    int info = 0;
    {
      const auto blas = blas_guard();
      dlauum_("U", &nb, u.data(), &nb, &info);
    }
    if (info != 0) throw std::logic_error("framed Cholesky: dlauum failed");
    m.w.triangularView<Eigen::Lower>() -= u.reverse();  // U's upper triangle, reversed
  }
}

FramedCholesky::~FramedCholesky() = default;

bool FramedCholesky::update(const SparseMatrix& a, const std::vector<int>* changed, int max_frame) {
  Impl& m = *impl_;
  const int n_old = static_cast<int>(m.factored.rows());
  const int n = static_cast<int>(a.rows());
  if (n < n_old || m.factor == nullptr) return false;
  // Changed rows of F not yet in the frame: they join it as extra rows (eq. (28)) while few.
  std::vector<int> outside;
  const auto framed = [&](int r) { return m.in_frame[static_cast<size_t>(r)] != 0; };
  if (changed) {
    for (int r : *changed) {
      if (r < 0 || r >= n) return false;
      if (r < n_old && !framed(r)) outside.push_back(r);
    }
  } else {
    for (int r = 0; r < n_old; ++r)
      if (!framed(r) && !same_row(a, m.factored, r)) outside.push_back(r);
  }
  std::sort(outside.begin(), outside.end());
  outside.erase(std::unique(outside.begin(), outside.end()), outside.end());
  if (static_cast<int>(m.extra.rows.size() + outside.size()) > kMaxExtraRows) return false;
  // The frame it would make: the old one, the new DOFs, the extra rows (below).
  if (static_cast<long>(n_old - m.n_f) + (n - n_old) + static_cast<long>(outside.size()) +
          static_cast<long>(m.extra.rows.size()) >
      max_frame)
    return false;
  std::optional<Extra> extra;
  if (!outside.empty()) {
    extra = m.extended(m.extra, outside);
    if (!extra) return false;
  }
  const Extra& x = extra ? *extra : m.extra;
  // The frame: the old one in its elimination order, the new DOFs, then the extra rows.
  const int nb_old = n_old - m.n_f, nx = static_cast<int>(x.rows.size());
  const int nb = nb_old + (n - n_old) + nx;
  std::vector<int> frame(frame_.begin(), frame_.begin() + nb_old);
  for (int r = n_old; r < n; ++r) frame.push_back(r);
  frame.insert(frame.end(), x.rows.begin(), x.rows.end());
  std::vector<int> pos(static_cast<size_t>(n), -1);
  for (int j = 0; j < nb; ++j) pos[static_cast<size_t>(frame[static_cast<size_t>(j)])] = j;
  // S' = A'_BB - W (eq. (26)), lower triangle; W is zero on the new DOFs. With extra rows,
  // W'' of eq. (28) over the old frame and them.
  // Written column by column, the lower triangle only (dpotrf and the solves read no other):
  // zeroing and copying whole squares was half of an update's time besides dpotrf.
  Eigen::MatrixXd s(nb, nb);
  const Eigen::MatrixXd& w = x.empty() ? m.w : x.w;  // over [old frame, X]
  const int n_new = nb - nb_old - nx;
  for (int j = 0; j < nb; ++j) {
    auto col = s.col(j);
    if (j < nb_old) {
      col.segment(j, nb_old - j) = -w.col(j).segment(j, nb_old - j);
      col.segment(nb_old, n_new).setZero();
      col.tail(nx) = -w.col(j).segment(nb_old, nx);
    } else if (j < nb_old + n_new) {
      col.tail(nb - j).setZero();
    } else {
      const int k = j - nb_old - n_new;  // X's column in w
      col.tail(nb - j) = -w.col(nb_old + k).segment(nb_old + k, nx - k);
    }
  }
  for (int j = 0; j < nb; ++j)
    for (SparseMatrix::InnerIterator it(a, frame[static_cast<size_t>(j)]); it; ++it) {
      const int i = pos[static_cast<size_t>(it.index())];
      if (i >= j) s(i, j) += it.value();
    }
  int info = 0;
  if (nb > 0) {
    const auto blas = blas_guard();
    dpotrf_("L", &nb, s.data(), &nb, &info);
  }
  if (info != 0) return false;  // not positive definite: the caller refactors (and diagnoses)
  if (extra) {
    for (int r : outside) m.in_frame[static_cast<size_t>(r)] = 1;
    m.extra = std::move(*extra);
  }
  m.schur = std::move(s);
  m.updated = true;
  frame_ = std::move(frame);
  rows_ = n;
  ++updates_;
  return true;
}

Eigen::MatrixXd FramedCholesky::solve(const Eigen::MatrixXd& b) const {
  if (b.rows() != rows_) throw std::invalid_argument("FramedCholesky::solve: size mismatch");
  const Impl& m = *impl_;
  const Eigen::Index cols = b.cols();
  if (rows_ == 0 || cols == 0) return Eigen::MatrixXd::Zero(rows_, cols);
  const int n_old = static_cast<int>(m.factored.rows());
  const int nb_old = n_old - m.n_f, nb = static_cast<int>(frame_.size());
  if (!m.updated) {
    Eigen::MatrixXd bp(n_old, cols);
    for (int k = 0; k < n_old; ++k) bp.row(k) = b.row(m.perm[static_cast<size_t>(k)]);
    const Eigen::MatrixXd xp = m.triangular_solve(CHOLMOD_Lt, m.triangular_solve(CHOLMOD_L, bp));
    Eigen::MatrixXd x(rows_, cols);
    for (int k = 0; k < n_old; ++k) x.row(m.perm[static_cast<size_t>(k)]) = xp.row(k);
    return x;
  }
  // Eq. (27): z = L^-1 P b with the kept factor; its frame rows give r_B = b_B - L_BF z_F.
  // Extra rows X (eq. (29)): their entries of b are left out of z and enter the frame's solve
  // with T_XX Y^T z_F; the back substitution then solves with A_F'F'.
  const Extra& ex = m.extra;
  const int nx = static_cast<int>(ex.rows.size());
  Eigen::MatrixXd bp(n_old, cols);
  for (int k = 0; k < n_old; ++k) bp.row(k) = b.row(m.perm[static_cast<size_t>(k)]);
  Eigen::MatrixXd b_x(nx, cols);
  for (int j = 0; j < nx; ++j) {
    b_x.row(j) = bp.row(ex.positions[static_cast<size_t>(j)]);
    bp.row(ex.positions[static_cast<size_t>(j)]).setZero();
  }
  Eigen::MatrixXd z = m.triangular_solve(CHOLMOD_L, bp);
  Eigen::MatrixXd x_b(nb, cols);
  {
    const auto blas = blas_guard();
    Eigen::MatrixXd r_old = z.bottomRows(nb_old);
    lower_times(m.l_bb, false, r_old);
    for (int j = nb_old; j < nb - nx; ++j) x_b.row(j) = b.row(frame_[static_cast<size_t>(j)]);
    if (nx > 0) {
      const Eigen::MatrixXd tq = ex.t * (ex.y.transpose() * z.topRows(m.n_f));  // T_XX q_X
      r_old.noalias() += ex.q * tq;
      x_b.bottomRows(nx) = b_x + tq;
    }
    x_b.topRows(nb_old) = r_old;
    cholesky_solve(m.schur, x_b);
    // Back: L^T x_p = [z_F; L_BB^T x_B] returns x_B in its frame rows and x_F above them.
    Eigen::MatrixXd top = x_b.topRows(nb_old);
    lower_times(m.l_bb, true, top);
    z.bottomRows(nb_old) = top;
    if (nx > 0) {
      // Eq. (29): z_F - M x_X substituted back would solve with all of A_FF and give rows g_X
      // on X; g_X = Y^T z_F - Q^T x_B is known before it (E_X^T L_FF^-T = Y^T; the
      // substitution's frame rows are x_B), and taking Y T_XX g_X out of z_F zeroes them and
      // leaves F' solved with A_F'F'.
      auto z_f = z.topRows(m.n_f);
      z_f.noalias() -= ex.m * x_b.bottomRows(nx);
      const Eigen::MatrixXd g_x = ex.y.transpose() * z_f - ex.q.transpose() * x_b.topRows(nb_old);
      z_f.noalias() -= ex.y * (ex.t * g_x);
    }
  }
  const Eigen::MatrixXd xp = m.triangular_solve(CHOLMOD_Lt, z);
  Eigen::MatrixXd x(rows_, cols);
  for (int k = 0; k < m.n_f; ++k) x.row(m.perm[static_cast<size_t>(k)]) = xp.row(k);
  for (int j = 0; j < nb; ++j) x.row(frame_[static_cast<size_t>(j)]) = x_b.row(j);
  return x;
}

int FramedCholesky::extra_rows() const { return static_cast<int>(impl_->extra.rows.size()); }

Vector FramedCholesky::solve(const Vector& b) const { return solve(Eigen::MatrixXd(b)).col(0); }

std::vector<int> FramedCholesky::frame_around_changes(const SparseMatrix& previous,
                                                      const SparseMatrix& a, int dense, int rings) {
  const int n = static_cast<int>(a.rows()), n_old = static_cast<int>(previous.rows());
  std::vector<int> changed;
  for (int r = 0; r < n; ++r)
    if (r >= n_old || !same_row(a, previous, r)) changed.push_back(r);
  return frame_around(a, changed, dense, rings);
}

std::vector<int> FramedCholesky::frame_around(const SparseMatrix& a,
                                              const std::vector<int>& changed, int dense,
                                              int rings) {
  const int n = static_cast<int>(a.rows());
  std::vector<char> in(static_cast<size_t>(n), 0);
  std::vector<int> layer;
  for (int r : changed) {
    if (r < 0 || r >= n || in[static_cast<size_t>(r)]) continue;
    in[static_cast<size_t>(r)] = 1;
    if (r >= dense) layer.push_back(r);
  }
  for (int ring = 0; ring < rings && !layer.empty(); ++ring) {
    std::vector<int> next;
    for (int r : layer)
      for (SparseMatrix::InnerIterator it(a, r); it; ++it) {
        const int c = static_cast<int>(it.index());
        if (in[static_cast<size_t>(c)]) continue;
        in[static_cast<size_t>(c)] = 1;
        if (c >= dense) next.push_back(c);
      }
    layer = std::move(next);
  }
  std::vector<int> frame;
  for (int r = 0; r < n; ++r)
    if (in[static_cast<size_t>(r)]) frame.push_back(r);
  return frame;
}

}  // namespace stc
