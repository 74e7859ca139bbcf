// OpenBLAS's kernels for this CPU (solve/blas_kernels.hpp).
#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

namespace stc {
namespace {

TEST(BlasKernels, PreAvx2CoresAreReplacedWhereTheCpuHasTheUnits) {
  const CpuVectorUnits avx512{true, true}, avx2{false, true}, none{false, false};
  // OpenBLAS 0.3.21 on an Emerald Rapids Xeon (family 6, model 207) says Prescott.
  EXPECT_EQ(better_blas_coretype("Prescott", avx512), "SkylakeX");
  EXPECT_EQ(better_blas_coretype("Prescott", avx2), "Haswell");
  EXPECT_EQ(better_blas_coretype("Prescott", none), "");
  EXPECT_EQ(better_blas_coretype("NEHALEM", avx2), "Haswell");  // any case
  EXPECT_EQ(better_blas_coretype("Barcelona", avx512), "SkylakeX");
  EXPECT_EQ(better_blas_coretype("Sandybridge", avx2), "Haswell");
}

TEST(BlasKernels, ItsOwnChoiceForACpuItKnowsIsKept) {
  const CpuVectorUnits avx512{true, true};
  for (const char* core : {"Haswell", "SkylakeX", "Cooperlake", "SapphireRapids", "Zen", ""})
    EXPECT_EQ(better_blas_coretype(core, avx512), "") << core;
}

// This test program starts as the others do (test/common/unit_main.cpp): the OpenBLAS it runs
// uses the kernels of this CPU's vector units, whatever OpenBLAS's own detection said.
TEST(BlasKernels, ThisProcessRunsTheCpusKernels) {
  const std::string core = blas_corename();
  if (core.empty()) GTEST_SKIP() << "the loaded BLAS is not OpenBLAS";
  if (std::getenv("OPENBLAS_CORETYPE") && better_blas_coretype(core, cpu_vector_units()) != "")
    GTEST_SKIP() << "OPENBLAS_CORETYPE was set by the caller";
  EXPECT_EQ(better_blas_coretype(core, cpu_vector_units()), "")
      << "OpenBLAS runs its " << core << " kernels on a CPU with "
      << (cpu_vector_units().avx512 ? "AVX-512" : "AVX2");
}

}  // namespace
}  // namespace stc
