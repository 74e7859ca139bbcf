#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include "solve/blas_guard.hpp"
#include "solve/upper_triangle.hpp"

#include <Eigen/CholmodSupport>

#include <algorithm>
#include <stdexcept>

namespace stc {

// Eigen's wrapper drives CHOLMOD's factorization: cholmod_analyze + cholmod_factorize with
// supernodal = CHOLMOD_SUPERNODAL (or CHOLMOD_SIMPLICIAL, LL^T), of the upper triangle. Solves call
// cholmod_solve on the factor directly, each with its own cholmod_common: Eigen's solve() goes
// through the one cholmod_common it keeps (workspace counters, status), so two threads solving with
// one factor would race on it. The factor itself is only read by cholmod_solve, so a const
// SparseCholesky may be shared by threads (the condensed part's factor: the loop and the ROS
// display thread, recovery/). Supernodal factorizations and solves call the BLAS: they hold
// blas_guard() (solve/blas_guard.hpp), which serializes them when the BLAS is not thread-safe.
template <typename Llt>
struct FactorOf : Llt {
  cholmod_factor* factor() const { return this->m_cholmodFactor; }
};

namespace {

using ColMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// Where a failed factorization stopped: L->minor, in the permuted order L->Perm (exact for a
// simplicial factor; a supernodal one reports its supernode's first column).
int failed_column(const cholmod_factor* l) {
  if (!l || l->minor >= l->n) return -1;
  return l->Perm ? static_cast<const int*>(l->Perm)[l->minor] : static_cast<int>(l->minor);
}

}  // namespace

ColMatrix upper_triangle(const SparseMatrix& a) {
  ColMatrix col(a.rows(), a.cols());
  int count = 0;
  for (int r = 0; r < a.outerSize(); ++r)
    for (SparseMatrix::InnerIterator it(a, r); it; ++it) count += it.col() <= r;
  col.resizeNonZeros(count);
  int* outer = col.outerIndexPtr();
  int* inner = col.innerIndexPtr();
  double* value = col.valuePtr();
  int out = 0;
  for (int r = 0; r < a.outerSize(); ++r) {  // row r of A: column r of the upper triangle
    outer[r] = out;
    for (SparseMatrix::InnerIterator it(a, r); it; ++it)
      if (it.col() <= r) inner[out] = static_cast<int>(it.col()), value[out++] = it.value();
  }
  outer[a.outerSize()] = out;
  return col;
}

struct SparseCholesky::Impl {
  FactorOf<Eigen::CholmodSupernodalLLT<ColMatrix, Eigen::Upper>> supernodal;
  FactorOf<Eigen::CholmodSimplicialLLT<ColMatrix, Eigen::Upper>> simplicial;
  CholeskyMethod method = CholeskyMethod::kSupernodal;

  // X = A^-1 B, B column-major with rows() rows. Thread-safe (see above).
  Eigen::MatrixXd solve(const double* b, int rows, int cols) const {
    cholmod_factor* factor =
        method == CholeskyMethod::kSimplicial ? simplicial.factor() : supernodal.factor();
    cholmod_common common;
    cholmod_start(&common);
    common.print = 0;
    cholmod_dense rhs{};
    rhs.nrow = rhs.d = static_cast<size_t>(rows);
    rhs.ncol = static_cast<size_t>(cols);
    rhs.nzmax = rhs.nrow * rhs.ncol;
    rhs.x = const_cast<double*>(b);  // read only: cholmod_solve writes a new matrix
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* x = nullptr;
    {
      const auto blas =
          method == CholeskyMethod::kSimplicial ? std::unique_lock<std::mutex>() : blas_guard();
      x = cholmod_solve(CHOLMOD_A, factor, &rhs, &common);
    }
    if (!x) {
      cholmod_finish(&common);
      throw std::runtime_error("sparse Cholesky (CHOLMOD): the solve failed (out of memory?)");
    }
    Eigen::MatrixXd out =
        Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x), rows, cols);
    cholmod_free_dense(&x, &common);
    cholmod_finish(&common);
    return out;
  }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;

SparseCholesky::SparseCholesky(const SparseMatrix& a, CholeskyMethod method,
                               CholeskyOrdering ordering)
    : impl_(std::make_unique<Impl>()), rows_(static_cast<int>(a.rows())) {
  impl_->method = method;
  blas_info();  // before CHOLMOD's first call: its threads settled (solve/blas_guard.hpp)
  if (rows_ == 0) return;
  if (ordering == CholeskyOrdering::kAmd)
    for (cholmod_common* c : {&impl_->simplicial.cholmod(), &impl_->supernodal.cholmod()}) {
      c->nmethods = 1;
      c->method[0].ordering = CHOLMOD_AMD;
    }
  const ColMatrix col = upper_triangle(a);
  // Failure is reported by the exception below; callers that probe (the Cholesky-PCG falls
  // back on failure) must not leave CHOLMOD's "not positive definite" warning on stderr.
  Eigen::ComputationInfo info;
  if (method == CholeskyMethod::kSimplicial) {
    impl_->simplicial.cholmod().print = 0;
    impl_->simplicial.compute(col);
    info = impl_->simplicial.info();
  } else {
    impl_->supernodal.cholmod().print = 0;
    const auto blas = blas_guard();
    impl_->supernodal.compute(col);
    info = impl_->supernodal.info();
  }
  if (info != Eigen::Success)
    throw std::runtime_error(
        "sparse Cholesky (CHOLMOD): matrix not positive definite - a part of the mesh is "
        "neither fixed nor held by the interface");
}

int SparseCholesky::first_failing_column(const SparseMatrix& a) {
  if (a.rows() == 0) return -1;
  FactorOf<Eigen::CholmodSimplicialLLT<ColMatrix, Eigen::Lower>> probe;
  probe.cholmod().print = 0;
  probe.cholmod().nmethods = 1;
  probe.cholmod().method[0].ordering = CHOLMOD_AMD;
  probe.compute(ColMatrix(a));
  return probe.info() == Eigen::Success ? -1 : failed_column(probe.factor());
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& b) const {
  if (rows_ == 0 || b.cols() == 0) return Eigen::MatrixXd::Zero(rows_, b.cols());
  if (b.rows() != rows_) throw std::invalid_argument("SparseCholesky::solve: size mismatch");
  return impl_->solve(b.data(), rows_, static_cast<int>(b.cols()));
}

Vector SparseCholesky::solve(const Vector& b) const {
  if (rows_ == 0) return Vector::Zero(0);
  if (b.size() != rows_) throw std::invalid_argument("SparseCholesky::solve: size mismatch");
  return impl_->solve(b.data(), rows_, 1);
}

void solve_direct(const SparseMatrix& a, const Vector& b, Vector& x,
                  const std::vector<std::uint8_t>& constrained) {
  const int n = static_cast<int>(a.rows());
  if (x.size() != n) x = Vector::Zero(n);
  std::vector<int> free_of(static_cast<size_t>(n), -1);
  std::vector<int> free;
  for (int i = 0; i < n; ++i)
    if (constrained.empty() || !constrained[static_cast<size_t>(i)]) {
      free_of[static_cast<size_t>(i)] = static_cast<int>(free.size());
      free.push_back(i);
    }
  Vector xc = x;
  for (int i : free) xc[i] = 0;
  const Vector rhs_all = b - a * xc;
  std::vector<Eigen::Triplet<double, int>> t;
  for (int r = 0; r < n; ++r) {
    if (free_of[static_cast<size_t>(r)] < 0) continue;
    for (SparseMatrix::InnerIterator it(a, r); it; ++it)
      if (free_of[static_cast<size_t>(it.col())] >= 0)
        t.emplace_back(free_of[static_cast<size_t>(r)], free_of[static_cast<size_t>(it.col())],
                       it.value());
  }
  SparseMatrix aff(static_cast<int>(free.size()), static_cast<int>(free.size()));
  aff.setFromTriplets(t.begin(), t.end());
  Vector rhs(static_cast<int>(free.size()));
  for (size_t k = 0; k < free.size(); ++k) rhs[static_cast<int>(k)] = rhs_all[free[k]];
  const Vector xf = SparseCholesky(aff).solve(rhs);
  for (size_t k = 0; k < free.size(); ++k) x[free[k]] = xf[static_cast<int>(k)];
}

}  // namespace stc
