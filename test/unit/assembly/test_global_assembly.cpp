// Global assembly (docs/DESIGN.md eq. (5)): assemble_block writes compressed rows directly
// from the elements; against the sum of the element triplets (Eigen's setFromTriplets), on
// square and rectangular blocks, with fixed nodes and nodes in no listed tet. add_difference
// (a cut's update by difference) keeps untouched rows bit for bit, merges the touched ones,
// appends new rows and drops what cancels.
#include "common/meshes.hpp"
#include "soft_tissue_cutting/assembly/element_cache.hpp"
#include "soft_tissue_cutting/assembly/global_assembly.hpp"

#include <gtest/gtest.h>

#include <numeric>

namespace stc {
namespace {

SparseMatrix by_triplets(const TetMesh& mesh, const ElementStiffnessCache& elements,
                         const std::vector<int>& tets, const DofMap& rows, const DofMap& cols) {
  std::vector<Triplet> t;
  add_element_triplets(mesh, elements, tets, rows.row_of, cols.row_of, t);
  SparseMatrix k(rows.rows(), cols.rows());
  k.setFromTriplets(t.begin(), t.end());
  return k;
}

void expect_same(const SparseMatrix& direct, const SparseMatrix& reference, const char* what) {
  ASSERT_EQ(direct.rows(), reference.rows()) << what;
  ASSERT_EQ(direct.cols(), reference.cols()) << what;
  EXPECT_TRUE(direct.isCompressed()) << what;
  EXPECT_EQ(direct.nonZeros(), reference.nonZeros()) << what << ": same pattern";
  ASSERT_GT(reference.nonZeros(), 0) << what;
  const double scale = SparseMatrix(reference).coeffs().cwiseAbs().maxCoeff();
  const SparseMatrix difference = direct - reference;
  const double largest = difference.nonZeros() ? difference.coeffs().cwiseAbs().maxCoeff() : 0;
  EXPECT_LE(largest, 1e-14 * scale) << what;
  for (int r = 0; r < direct.rows(); ++r)  // columns sorted in every row
    for (int p = direct.outerIndexPtr()[r] + 1; p < direct.outerIndexPtr()[r + 1]; ++p)
      ASSERT_LT(direct.innerIndexPtr()[p - 1], direct.innerIndexPtr()[p]) << what << ", row " << r;
}

TEST(GlobalAssembly, DirectCompressedRowsEqualTheSumOfElementTriplets) {
  const TetMesh mesh = test::cube_mesh();  // 384 tets, 125 nodes
  const ElementStiffnessCache elements(mesh, Material{3000.0, 0.45, 1000.0});
  std::vector<std::uint8_t> fixed(static_cast<size_t>(mesh.num_nodes()), 0);
  for (int n = 0; n < mesh.num_nodes(); ++n)
    fixed[static_cast<size_t>(n)] = mesh.nodes[n].z() < 1e-9;
  // Part 1: the tets below the middle; its nodes listed in reverse (rows not in node order).
  std::vector<int> part1, part2;
  for (int t = 0; t < mesh.num_tets(); ++t) {
    double z = 0;
    for (int v : mesh.tets[static_cast<size_t>(t)]) z += 0.25 * mesh.nodes[v].z();
    (z < 0.02 ? part1 : part2).push_back(t);
  }
  std::vector<int> all(static_cast<size_t>(mesh.num_nodes()));
  std::iota(all.begin(), all.end(), 0);
  std::vector<int> reversed(all.rbegin(), all.rend());
  const DofMap whole = make_dof_map(mesh.num_nodes(), reversed, fixed);
  expect_same(assemble_stiffness(mesh, elements, part1, whole),
              by_triplets(mesh, elements, part1, whole, whole), "part 1, all nodes");
  // Rectangular: rows on the upper nodes, columns on the lower ones (an off-diagonal block).
  std::vector<int> upper, lower;
  for (int n : all) (mesh.nodes[n].z() > 0.015 ? upper : lower).push_back(n);
  const DofMap rows = make_dof_map(mesh.num_nodes(), upper, fixed);
  const DofMap cols = make_dof_map(mesh.num_nodes(), lower, fixed);
  expect_same(assemble_block(mesh, elements, part1, rows, cols),
              by_triplets(mesh, elements, part1, rows, cols), "upper x lower");
  expect_same(assemble_block(mesh, elements, part1, cols, rows),
              by_triplets(mesh, elements, part1, cols, rows), "lower x upper");
  expect_same(assemble_stiffness(mesh, elements, part2, whole),
              by_triplets(mesh, elements, part2, whole, whole), "part 2, all nodes");
  // No tets: an empty block of the right shape.
  const SparseMatrix empty = assemble_block(mesh, elements, {}, rows, cols);
  EXPECT_EQ(empty.nonZeros(), 0);
  EXPECT_EQ(empty.rows(), rows.rows());
}

TEST(GlobalAssembly, AddDifferenceKeepsUntouchedRowsAndDropsWhatCancels) {
  // a: 4 x 4, symmetric; d touches rows 1 and 2, cancels the (1, 2) coupling, adds a new
  // DOF 4 coupled to row 2.
  std::vector<Triplet> ta = {{0, 0, 4},  {0, 1, -1}, {1, 0, -1}, {1, 1, 4},
                             {1, 2, -1}, {2, 1, -1}, {2, 2, 4},  {3, 3, 2}};
  SparseMatrix a(4, 4);
  a.setFromTriplets(ta.begin(), ta.end());
  // -1 + (1 - 1e-15): a coupling that cancels to rounding, not to zero.
  std::vector<Triplet> td = {{1, 2, 1 - 1e-15}, {2, 1, 1 - 1e-15}, {1, 1, 0.5},
                             {2, 4, -0.5},      {4, 2, -0.5},      {4, 4, 1.0}};
  SparseMatrix d(5, 5);
  d.setFromTriplets(td.begin(), td.end());
  const std::vector<std::uint8_t> touched = {0, 1, 1, 0, 1};
  SparseMatrix spare;
  const SparseMatrix before = a;
  add_difference(a, d, touched, 1e-12, spare);
  ASSERT_EQ(a.rows(), 5);
  EXPECT_EQ(a.coeff(0, 0), before.coeff(0, 0));  // untouched rows as they were
  EXPECT_EQ(a.coeff(0, 1), before.coeff(0, 1));
  EXPECT_EQ(a.coeff(3, 3), before.coeff(3, 3));
  EXPECT_EQ(a.coeff(1, 1), 4.5);
  EXPECT_EQ(a.coeff(2, 4), -0.5);
  EXPECT_EQ(a.coeff(4, 2), -0.5);
  EXPECT_EQ(a.coeff(4, 4), 1.0);
  EXPECT_EQ(a.nonZeros(), 8 - 2 + 3);  // (1, 2), (2, 1) dropped; (2, 4), (4, 2), (4, 4) added
  for (int r = 0; r < a.rows(); ++r)
    for (SparseMatrix::InnerIterator it(a, r); it; ++it)
      EXPECT_NE(it.value(), 0.0) << r << ", " << it.index();
}

// The rows before the first touched one are kept in place and the rest rebuilt: against a + d
// computed densely, for changes that begin at every row (none, the first, the middle, new rows
// only), with new DOFs appended.
TEST(GlobalAssembly, AddDifferenceEqualsTheDenseSumWhereverTheChangeBegins) {
  const int n_old = 24, n = 27;
  std::vector<Triplet> ta;
  for (int r = 0; r < n_old; ++r) {
    ta.emplace_back(r, r, 10.0 + r);
    for (int c = r + 1; c < n_old; c += 1 + (r * 7 + c) % 5) {
      const double v = -0.1 * (1 + (r + 2 * c) % 7);
      ta.emplace_back(r, c, v);
      ta.emplace_back(c, r, v);
    }
  }
  SparseMatrix a0(n_old, n_old);
  a0.setFromTriplets(ta.begin(), ta.end());
  for (int first : {0, 1, 11, n_old - 1, n_old}) {
    std::vector<Triplet> td;
    std::vector<std::uint8_t> touched(static_cast<size_t>(n), 0);
    for (int r = first; r < n; r += 3)
      for (int c = first; c < n; c += 4) {
        const double v = 0.05 * (1 + (r + c) % 3);
        td.emplace_back(r, c, v);
        td.emplace_back(c, r, v);
        touched[static_cast<size_t>(r)] = touched[static_cast<size_t>(c)] = 1;
      }
    for (int r = n_old; r < n; ++r) {
      td.emplace_back(r, r, 5.0);
      touched[static_cast<size_t>(r)] = 1;
    }
    SparseMatrix d(n, n);
    d.setFromTriplets(td.begin(), td.end());
    SparseMatrix a = a0, spare;
    add_difference(a, d, touched, 1e-12, spare);
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(n, n);
    expected.topLeftCorner(n_old, n_old) = Eigen::MatrixXd(a0);
    expected += Eigen::MatrixXd(d);
    ASSERT_EQ(a.rows(), n) << first;
    ASSERT_TRUE(a.isCompressed()) << first;
    EXPECT_EQ((Eigen::MatrixXd(a) - expected).cwiseAbs().maxCoeff(), 0.0) << first;
    EXPECT_EQ(a.nonZeros(), (expected.array() != 0).count()) << first;  // no stored zeros
    for (int r = 0; r < first && r < n_old; ++r)  // untouched rows: bit for bit
      for (SparseMatrix::InnerIterator it(a, r), ref(a0, r); it || ref; ++it, ++ref) {
        ASSERT_TRUE(it && ref) << first << " row " << r;
        EXPECT_EQ(it.index(), ref.index());
        EXPECT_EQ(it.value(), ref.value());
      }
  }
}

}  // namespace
}  // namespace stc
