// The Schur complement by one partial factorization (solve/schur_complement.hpp) against the
// dense formula S = A_BB - A_BA A_AA^-1 A_AB: on a grid Laplacian split into an interior and
// a boundary (the whole matrix singular: only B holds A, as a condensed part that the interface
// alone holds), the same with a Dirichlet row (SPD), and on the thigh's condensation (the
// condensed-part test compares K0 too, test_condensed_part.cpp).
#include "soft_tissue_cutting/solve/schur_complement.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <vector>

namespace stc {
namespace {

// A 3D grid graph Laplacian (k x k x k nodes, random positive edge weights) plus `ground` on
// node 0's diagonal; A = interior nodes, B = the grid's boundary nodes, in a scrambled order.
struct Split {
  SparseMatrix aa, ab, bb;
  Eigen::MatrixXd whole;  // dense, A then B
};

Split grid_split(int k, double ground, unsigned seed) {
  const int n = k * k * k;
  std::srand(seed);
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);
  auto id = [k](int x, int y, int z) { return (z * k + y) * k + x; };
  for (int z = 0; z < k; ++z)
    for (int y = 0; y < k; ++y)
      for (int x = 0; x < k; ++x)
        for (const auto& [dx, dy, dz] : {std::array<int, 3>{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}) {
          if (x + dx >= k || y + dy >= k || z + dz >= k) continue;
          const int i = id(x, y, z), j = id(x + dx, y + dy, z + dz);
          const double w = 0.5 + static_cast<double>(std::rand()) / RAND_MAX;
          m(i, i) += w, m(j, j) += w, m(i, j) -= w, m(j, i) -= w;
        }
  m(0, 0) += ground;
  std::vector<int> a, b;
  for (int z = 0; z < k; ++z)
    for (int y = 0; y < k; ++y)
      for (int x = 0; x < k; ++x) {
        const bool edge = x == 0 || y == 0 || z == 0 || x == k - 1 || y == k - 1 || z == k - 1;
        (edge ? b : a).push_back(id(x, y, z));
      }
  std::reverse(b.begin(), b.end());  // B's own order is not the grid's
  std::vector<int> order(a);
  order.insert(order.end(), b.begin(), b.end());
  Split s;
  s.whole.resize(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) s.whole(i, j) = m(order[i], order[j]);
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  s.aa = s.whole.topLeftCorner(na, na).sparseView();
  s.ab = s.whole.topRightCorner(na, nb).sparseView();
  s.bb = s.whole.bottomRightCorner(nb, nb).sparseView();
  return s;
}

double relative_error(const Split& s, const Eigen::MatrixXd& got) {
  const int na = static_cast<int>(s.aa.rows()), nb = static_cast<int>(s.bb.rows());
  const Eigen::MatrixXd aa = s.whole.topLeftCorner(na, na);
  const Eigen::MatrixXd ab = s.whole.topRightCorner(na, nb);
  const Eigen::MatrixXd want =
      s.whole.bottomRightCorner(nb, nb) - ab.transpose() * aa.llt().solve(ab);
  return (got - want).norm() / want.norm();
}

TEST(SchurComplement, EqualsTheDenseFormulaWhenOnlyBHoldsA) {
  const Split s = grid_split(7, 0.0, 1u);  // the whole Laplacian is singular
  const Eigen::MatrixXd got = schur_complement(s.aa, s.ab, s.bb);
  ASSERT_EQ(got.rows(), s.bb.rows());
  EXPECT_LT(relative_error(s, got), 1e-13);
  // S inherits the constant null vector: the shift taken off leaves no trace of it.
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(got.rows());
  EXPECT_LT((got * ones).norm(), 1e-12 * got.norm());
  EXPECT_LT((got - got.transpose()).norm(), 1e-15 * got.norm());
}

TEST(SchurComplement, EqualsTheDenseFormulaOnAnSpdMatrix) {
  const Split s = grid_split(6, 3.0, 2u);
  EXPECT_LT(relative_error(s, schur_complement(s.aa, s.ab, s.bb)), 1e-13);
}

TEST(SchurComplement, EmptyBlocksAndBadSizes) {
  const Split s = grid_split(4, 1.0, 3u);
  EXPECT_EQ(schur_complement(s.aa, SparseMatrix(s.aa.rows(), 0), SparseMatrix(0, 0)).rows(), 0);
  const Eigen::MatrixXd bb = schur_complement(SparseMatrix(0, 0), SparseMatrix(0, s.bb.rows()),
                                              s.bb);  // nothing to eliminate: S = A_BB
  EXPECT_EQ((bb - Eigen::MatrixXd(s.bb)).norm(), 0.0);
  EXPECT_THROW(schur_complement(s.aa, s.bb, s.bb), std::invalid_argument);
  // A_AA not positive definite: refused with a message, not a wrong S.
  SparseMatrix bad = s.aa;
  bad.coeffRef(0, 0) = -1;
  EXPECT_THROW(schur_complement(bad, s.ab, s.bb), std::runtime_error);
}

}  // namespace
}  // namespace stc
