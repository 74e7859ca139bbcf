// The elimination order with the dense interface rows last and the star pattern the symbolic
// factorization reads instead of their block (solve/interface_last_order.hpp, docs/DESIGN.md
// section 6.2 "Ordering"): the dense rows are AMD's, each set's come after its sparse rows,
// the star's symbolic factor is the whole pattern's (equal on the hybrid matrices of the thigh
// and a TetGen liver, a superset where the dense rows are not one block), and the factor
// solves exactly in both cases, filling no more than CAMD's order of the whole matrix.
#include "solve/interface_last_order.hpp"

#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/scene/scene_loader.hpp"
#include "soft_tissue_cutting/simulation/hybrid_model.hpp"
#include "soft_tissue_cutting/solve/framed_cholesky.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"

#include <gtest/gtest.h>
#include <Eigen/CholmodSupport>

#include <cmath>
#include <string>

namespace stc {
namespace {

ColMatrix upper_of(const SparseMatrix& a) {
  ColMatrix upper = ColMatrix(a).triangularView<Eigen::Upper>();
  upper.makeCompressed();
  return upper;
}

// CHOLMOD's symbolic factor of `pattern` (upper triangle) in the order `perm`: nnz(L), flops.
struct Symbolic {
  double lnz = 0, flops = 0;
};
Symbolic analyse(const ColMatrix& pattern, std::vector<int> perm) {
  cholmod_common c;
  cholmod_start(&c);
  c.print = 0;
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_GIVEN;
  c.postorder = false;
  c.supernodal = CHOLMOD_SUPERNODAL;
  ColMatrix copy = pattern;
  cholmod_sparse view = Eigen::viewAsCholmod(copy);
  view.stype = 1;
  cholmod_factor* f = cholmod_analyze_p(&view, perm.data(), nullptr, 0, &c);
  Symbolic s;
  if (f) s = {c.lnz, c.fl};
  cholmod_free_factor(&f, &c);
  cholmod_finish(&c);
  return s;
}

// CAMD of the whole matrix (the order before this one) with the same sets.
std::vector<int> camd_whole(const ColMatrix& upper, const std::vector<char>& in_frame) {
  cholmod_common c;
  cholmod_start(&c);
  ColMatrix copy = upper;
  cholmod_sparse view = Eigen::viewAsCholmod(copy);
  view.stype = 1;
  std::vector<int> member(in_frame.begin(), in_frame.end()), perm(in_frame.size());
  EXPECT_TRUE(cholmod_camd(&view, nullptr, 0, member.data(), perm.data(), &c));
  cholmod_finish(&c);
  return perm;
}

// Two cliques of `clique` rows each, with no entry between them, each tied by ten of its rows to
// its end of a tridiagonal chain of `chain` rows: both cliques are dense rows, not one block.
SparseMatrix two_cliques(int clique, int chain) {
  const int n = 2 * clique + chain;
  std::vector<Eigen::Triplet<double>> t;
  auto add = [&](int i, int j, double v) {
    t.emplace_back(i, j, v);
    if (i != j) t.emplace_back(j, i, v);
  };
  for (int q = 0; q < 2; ++q)
    for (int i = 0; i < clique; ++i)
      for (int j = 0; j < i; ++j) add(q * clique + i, q * clique + j, 0.5 + 0.1 * std::sin(i + j));
  for (int k = 0; k + 1 < chain; ++k) add(2 * clique + k, 2 * clique + k + 1, -1.0);
  for (int i = 0; i < 10; ++i) add(i, 2 * clique, -0.3), add(clique + i, n - 1, -0.3);
  for (int i = 0; i < n; ++i) add(i, i, i < 2 * clique ? clique + 2.0 : 4.0);
  SparseMatrix a(n, n);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

TEST(InterfaceLastOrder, DenseRowsAreTheRowsAboveAmdsThreshold) {
  const SparseMatrix a = two_cliques(120, 300);  // n = 540: threshold 10 sqrt(540) = 232
  std::vector<char> dense = dense_rows(a);
  EXPECT_EQ(std::count(dense.begin(), dense.end(), 1), 0) << "cliques of 121 rows are not dense";
  const SparseMatrix b = two_cliques(260, 100);  // n = 620: threshold 249, cliques of 261
  dense = dense_rows(b);
  for (int r = 0; r < 620; ++r) EXPECT_EQ(dense[static_cast<size_t>(r)], r < 520) << "row " << r;
}

TEST(InterfaceLastOrder, EachSetsDenseRowsComeAfterItsSparseRows) {
  const SparseMatrix a = two_cliques(260, 100);
  const std::vector<char> dense = dense_rows(a);
  std::vector<char> in_frame(620, 0);
  for (int r = 0; r < 620; r += 7) in_frame[static_cast<size_t>(r)] = 1;  // dense and sparse rows
  cholmod_common c;
  cholmod_start(&c);
  const std::vector<int> perm = order_dense_last(upper_of(a), dense, in_frame, c);
  cholmod_finish(&c);
  ASSERT_EQ(perm.size(), 620u);
  std::vector<int> sorted = perm;
  std::sort(sorted.begin(), sorted.end());
  for (int r = 0; r < 620; ++r) ASSERT_EQ(sorted[static_cast<size_t>(r)], r);
  // (set, dense) never decreases along the order.
  int last = 0;
  for (int r : perm) {
    const int key = 2 * in_frame[static_cast<size_t>(r)] + dense[static_cast<size_t>(r)];
    EXPECT_GE(key, last) << "row " << r;
    last = std::max(last, key);
  }
}

// On a hybrid matrix: the star's symbolic factor is the whole pattern's, the fill is no more
// than CAMD's order of the whole matrix gave (within 5 %), and the factor solves exactly.
// Without dense rows (a small interface) the order is CAMD's of the whole matrix.
void star_on_hybrid_matrix(const Scene& scene, const std::string& what, bool dense_interface) {
  const HybridModel h(scene);
  const SparseMatrix& a = h.hybrid_matrix();
  const int n = static_cast<int>(a.rows());
  const std::vector<char> dense = dense_rows(a);
  const int interface = 3 * static_cast<int>(h.partition().interface.size());
  const auto n_dense = std::count(dense.begin(), dense.end(), 1);
  std::printf("[ order    ] %s: %d rows, %d interface, %ld dense\n", what.c_str(), n, interface,
              static_cast<long>(n_dense));
  for (int r = interface; r < n; ++r) ASSERT_FALSE(dense[static_cast<size_t>(r)]) << what;
  // A frame around the last operation row, as after a cut there.
  std::vector<char> in_frame(static_cast<size_t>(n), 0);
  for (SparseMatrix::InnerIterator it(a, n - 1); it; ++it)
    in_frame[static_cast<size_t>(it.col())] = 1;
  const ColMatrix upper = upper_of(a);
  cholmod_common c;
  cholmod_start(&c);
  const std::vector<int> perm = order_dense_last(upper, dense, in_frame, c);
  cholmod_finish(&c);
  if (!dense_interface) {
    EXPECT_EQ(n_dense, 0) << what;
    EXPECT_EQ(perm, camd_whole(upper, in_frame)) << what;
    return;
  }
  ASSERT_GT(n_dense, interface / 2) << what << ": most interface rows are dense";
  const int hub = *std::find_if(perm.begin(), perm.end(),
                                [&](int r) { return dense[static_cast<size_t>(r)] != 0; });
  const Symbolic whole = analyse(upper, perm),
                 star = analyse(dense_star_pattern(upper, dense, hub), perm);
  EXPECT_EQ(star.lnz, whole.lnz) << what;
  EXPECT_EQ(star.flops, whole.flops) << what;
  const Symbolic camd = analyse(upper, camd_whole(upper, in_frame));
  std::printf("[ order    ] %s: %.1f MFlop, CAMD of the whole matrix %.1f\n", what.c_str(),
              star.flops / 1e6, camd.flops / 1e6);
  EXPECT_LE(star.flops, 1.05 * camd.flops) << what;
  std::vector<int> frame;
  for (int r = 0; r < n; ++r)
    if (in_frame[static_cast<size_t>(r)]) frame.push_back(r);
  const FramedCholesky factor(a, frame);
  const SparseCholesky fresh(a, CholeskyMethod::kSupernodal, CholeskyOrdering::kAmd);
  const Vector b = h.hybrid_rhs() + Vector::LinSpaced(n, -1.0, 1.0);
  const Vector ref = fresh.solve(b);
  EXPECT_LE((factor.solve(b) - ref).norm() / ref.norm(), 1e-12) << what;
}

TEST(InterfaceLastOrder, WithoutDenseRowsTheOrderIsCamdsOnThigh) {
  // The thigh's interface (115 nodes) couples no row past AMD's dense threshold (280).
  star_on_hybrid_matrix(make_thigh_scene(), "thigh", false);
}

TEST(InterfaceLastOrder, StarHasTheWholePatternsFactorOnTetgenLiver) {
  star_on_hybrid_matrix(
      load_scene(std::string(TISSUE_TEST_DATA_DIR) + "/../../config/scenes/liver_cut.yaml"),
      "TetGen liver", true);
}

// Dense rows that are two blocks with nothing between them: the star joins them, so its factor
// has more entries than the matrix needs, but it holds every entry of the matrix - a star that
// missed some would leave them out of the numerical factorization (CHOLMOD drops entries outside
// the analysed pattern) and the solve would be wrong.
TEST(InterfaceLastOrder, StarHoldsDenseRowsThatAreNotOneBlock) {
  const SparseMatrix a = two_cliques(260, 100);
  const std::vector<char> dense = dense_rows(a);
  const std::vector<char> none(620, 0);
  const ColMatrix upper = upper_of(a);
  cholmod_common c;
  cholmod_start(&c);
  const std::vector<int> perm = order_dense_last(upper, dense, none, c);
  cholmod_finish(&c);
  const Symbolic whole = analyse(upper, perm),
                 star = analyse(dense_star_pattern(upper, dense, perm[100]), perm);
  EXPECT_GT(star.lnz, whole.lnz);
  const FramedCholesky factor(a, {});
  const Vector b = Vector::LinSpaced(620, -1.0, 2.0);
  const Vector ref = Eigen::MatrixXd(a).llt().solve(b);
  EXPECT_LE((factor.solve(b) - ref).norm() / ref.norm(), 1e-12);
}

}  // namespace
}  // namespace stc
