// Synthetic SPD matrices for GPU tests and benchmarks (see test_matrices.hpp).
#include "soft_tissue_cutting/gpu/test_matrices.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace stc {
namespace gpu {
namespace {

using Triplet = Eigen::Triplet<double>;

// Symmetric off-diagonal pair (i, j) with value v plus |v| on both diagonals: the 2x2 block
// [|v| v; v |v|] is PSD, so adding it keeps the matrix SPD.
void add_pair(std::vector<Triplet>& t, int i, int j, double v) {
  t.emplace_back(i, j, v);
  t.emplace_back(j, i, v);
  t.emplace_back(i, i, std::abs(v));
  t.emplace_back(j, j, std::abs(v));
}

SparseMatrix build(int n, const std::vector<Triplet>& t) {
  SparseMatrix m(n, n);
  m.setFromTriplets(t.begin(), t.end());
  m.makeCompressed();
  return m;
}

void append(std::vector<Triplet>& t, const SparseMatrix& a) {
  for (int i = 0; i < a.outerSize(); ++i)
    for (SparseMatrix::InnerIterator it(a, i); it; ++it)
      t.emplace_back(i, int(it.col()), it.value());
}

}  // namespace

SparseMatrix elasticity_like(int nodes, int nx, int ny) {
  // B: a fixed SPD 3x3 "material" block; node stencil: 6 B on the diagonal, -B to each of the
  // 6 grid neighbours (missing neighbours act as fixed nodes, so the matrix stays SPD).
  const double b[3][3] = {{2.0, 0.5, 0.2}, {0.5, 2.0, 0.3}, {0.2, 0.3, 2.0}};
  std::vector<Triplet> t;
  t.reserve(std::size_t(nodes) * 63);
  for (int node = 0; node < nodes; ++node) {
    const int x = node % nx, y = (node / nx) % ny, z = node / (nx * ny);
    const int nb[6][3] = {{x - 1, y, z}, {x + 1, y, z}, {x, y - 1, z},
                          {x, y + 1, z}, {x, y, z - 1}, {x, y, z + 1}};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) t.emplace_back(3 * node + r, 3 * node + c, 6.0 * b[r][c]);
    for (const auto& q : nb) {
      if (q[0] < 0 || q[0] >= nx || q[1] < 0 || q[1] >= ny || q[2] < 0) continue;
      const int other = q[0] + nx * (q[1] + ny * q[2]);
      if (other >= nodes) continue;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) t.emplace_back(3 * node + r, 3 * other + c, -b[r][c]);
    }
  }
  return build(3 * nodes, t);
}

SparseMatrix with_dense_block(const SparseMatrix& a, int d, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Triplet> t;
  append(t, a);
  for (int i = 0; i < d; ++i)
    for (int j = i + 1; j < d; ++j) add_pair(t, i, j, u(rng));
  return build(int(a.rows()), t);
}

int max_offdiag_row(const SparseMatrix& a) {
  int best = 0;
  for (int i = 0; i < a.outerSize(); ++i) {
    int len = 0;
    for (SparseMatrix::InnerIterator it(a, i); it; ++it) len += it.col() != i;
    best = std::max(best, len);
  }
  return best;
}

SparseMatrix table2_matrix(int dof, int max_row, unsigned seed) {
  if (dof % 3 != 0 || max_row >= dof) throw std::runtime_error("table2_matrix: bad sizes");
  const int nodes = dof / 3;
  const int side = std::max(2, int(std::cbrt(double(nodes))));
  const SparseMatrix sparse = elasticity_like(nodes, side, side);
  // Largest interface block whose rows stay within max_row...
  int d = std::min(max_row + 1, dof);
  SparseMatrix a = with_dense_block(sparse, d, seed);
  while (max_offdiag_row(a) > max_row) a = with_dense_block(sparse, --d, seed);
  // ...then links from DOF 0 to DOFs outside the block until its row has exactly max_row.
  std::vector<Triplet> t;
  append(t, a);
  int len = 0;
  for (SparseMatrix::InnerIterator it(a, 0); it; ++it) len += it.col() != 0;
  std::mt19937 rng(seed + 7);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (int j = dof - 1; len < max_row && j >= d; --j) {
    if (a.coeff(0, j) != 0.0) continue;
    add_pair(t, 0, j, u(rng));
    ++len;
  }
  return build(dof, t);
}

Vector random_vector(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

}  // namespace gpu
}  // namespace stc
