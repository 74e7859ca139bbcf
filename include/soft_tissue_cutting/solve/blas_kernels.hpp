// OpenBLAS's kernels for this CPU (docs/DESIGN.md section 14, "BLAS kernels").
//
// Debian 12's OpenBLAS (0.3.21, built DYNAMIC_ARCH) picks its kernels from the CPU's family and
// model when it loads. A CPU newer than it knows gets its generic Prescott (SSE3) kernels even
// with AVX-512 on board: on an Intel Xeon of family 6, model 207 (Emerald Rapids) the frame
// updates and the condensation's dense products ran at a third of the speed (the organ liver's
// online cutting step: solve median 6.0-9.1 -> 4.1-4.2 ms with the SkylakeX kernels).
// OPENBLAS_CORETYPE chooses them, but OpenBLAS reads it only as it loads, before main(): the
// programs set it and start again (reexec_with_native_blas_kernels, first thing in main()).
#pragma once

#include <string>

namespace stc {

// What the CPU offers OpenBLAS's kernels.
struct CpuVectorUnits {
  bool avx512 = false;    // AVX-512 F, CD, BW, DQ and VL: OpenBLAS's SkylakeX kernels
  bool avx2_fma = false;  // AVX2 and FMA: its Haswell kernels
};
CpuVectorUnits cpu_vector_units();

// The kernels to ask for when OpenBLAS picked `corename` (openblas_get_corename(), any case):
// "SkylakeX" or "Haswell" when it picked one of its pre-AVX2 x86 cores (Prescott and the like)
// on a CPU that has those units; "" to leave its choice (it knew the CPU, or the CPU has
// neither).
std::string better_blas_coretype(const std::string& corename, const CpuVectorUnits& cpu);

// First thing in main(): when the loaded OpenBLAS runs pre-AVX2 kernels on a CPU with AVX2 or
// AVX-512 and OPENBLAS_CORETYPE is unset, sets it and executes the program again (the same
// arguments and process id; nothing has run yet). Returns otherwise, and when the exec fails.
void reexec_with_native_blas_kernels(char** argv);

// openblas_get_corename() of the loaded BLAS, or "" for a BLAS that is not OpenBLAS.
std::string blas_corename();

}  // namespace stc
