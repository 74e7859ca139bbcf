// main() of tissue_bench: Google Benchmark's, after OpenBLAS's kernels are those of this CPU
// (solve/blas_kernels.hpp): a benchmark measures what the programs run.
#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <benchmark/benchmark.h>

int main(int argc, char** argv) {
  stc::reexec_with_native_blas_kernels(argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
