// CHOLMOD's supernodal factorizations and solves from two threads at once (what a region move's
// worker and the ROS display thread do beside the loop) give the same numbers as one at a time,
// whatever BLAS the loader picked: solve/blas_guard.hpp serializes the calls when the BLAS is
// not thread-safe (Debian's libopenblas0-serial). Without the guard, on that BLAS, this test
// fails (the comparison below differs on some repetitions).
#include "common/test_matrices.hpp"
#include "soft_tissue_cutting/solve/sparse_cholesky.hpp"
#include "solve/blas_guard.hpp"

#include <gtest/gtest.h>

#include <dlfcn.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

namespace stc {
namespace {

struct Problem {
  SparseMatrix a;
  Vector b, x;  // x: A^-1 b, solved alone
};

Problem problem(int side, unsigned seed) {
  Problem p;
  p.a = test::with_dense_block(test::elasticity_like(side * side * side, side, side), 60, seed);
  p.b = test::random_vector(p.a.rows(), seed);
  p.x = SparseCholesky(p.a).solve(p.b);
  return p;
}

// Two threads, each factoring its own matrix and solving `rounds` times; counts the results
// that are not bit for bit the ones computed alone (same matrix, same BLAS, one thread).
int differing_when_concurrent(const std::vector<Problem>& problems, int rounds) {
  std::atomic<int> differing{0};
  std::vector<std::thread> threads;
  for (const Problem& p : problems)
    threads.emplace_back([&p, rounds, &differing] {
      for (int r = 0; r < rounds; ++r) {
        const Vector x = SparseCholesky(p.a).solve(p.b);
        if (x != p.x) ++differing;
      }
    });
  for (std::thread& t : threads) t.join();
  return differing.load();
}

TEST(BlasGuard, ConcurrentSupernodalCholeskyMatchesOneThreadAtATime) {
  std::printf("BLAS: %s (calls %s)\n",
              blas_info().config.empty() ? "not OpenBLAS" : blas_info().config.c_str(),
              blas_info().serialized ? "serialized" : "concurrent");
  // 3D elasticity-like systems of 4.1k and 5.2k DOF with a dense 60-DOF block: supernodes
  // large enough that the factorization and the solve run in the BLAS.
  const std::vector<Problem> problems = {problem(11, 1), problem(12, 2)};
  EXPECT_EQ(differing_when_concurrent(problems, 40), 0) << "as detected";
  force_blas_serialization(true);
  EXPECT_EQ(differing_when_concurrent(problems, 10), 0) << "serialized";
  reset_blas_serialization();
}

// A region move's worker runs CHOLMOD's OpenMP regions inline like the loop's thread
// (settle_openmp_on_this_thread): libgomp keeps max-active-levels per thread, and a worker
// that kept the default condensed the organ liver in 1.0 s instead of 0.55 s.
TEST(BlasGuard, AWorkerThreadRunsCholmodsOpenMpRegionsInline) {
  using GetFn = int (*)();
  const auto get = reinterpret_cast<GetFn>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
  if (!get || std::getenv("OMP_THREAD_LIMIT") || std::getenv("OMP_MAX_ACTIVE_LEVELS"))
    GTEST_SKIP() << "no OpenMP runtime in the process, or the user chose its limits";
  const Problem p = problem(8, 3);
  int before = -1, after = -1;
  std::thread worker([&] {
    before = get();
    settle_openmp_on_this_thread();
    const Vector x = SparseCholesky(p.a).solve(p.b);
    after = get();
    EXPECT_LE((x - p.x).norm(), 1e-12 * p.x.norm());
  });
  worker.join();
  EXPECT_NE(before, 0) << "a new thread starts from libgomp's defaults";
  EXPECT_EQ(after, 0) << "the worker's OpenMP regions are still active";
}

}  // namespace
}  // namespace stc
