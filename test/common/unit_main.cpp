// main() of the unit tests: GoogleTest's, after OpenBLAS's kernels are those of this CPU
// (solve/blas_kernels.hpp), so tests that time or stress the BLAS run it as the programs do.
#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <gtest/gtest.h>

int main(int argc, char** argv) {
  stc::reexec_with_native_blas_kernels(argv);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
