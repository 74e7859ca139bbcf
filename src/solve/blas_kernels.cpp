#include "soft_tissue_cutting/solve/blas_kernels.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdlib>

namespace stc {

CpuVectorUnits cpu_vector_units() {
  CpuVectorUnits cpu;
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  cpu.avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
               __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
               __builtin_cpu_supports("avx512vl");
  cpu.avx2_fma = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif
  return cpu;
}

std::string better_blas_coretype(const std::string& corename, const CpuVectorUnits& cpu) {
  std::string core = corename;
  std::transform(core.begin(), core.end(), core.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  // OpenBLAS's x86-64 cores without AVX2 (its fallbacks for a CPU it does not know). A core it
  // named for AVX2 or later hardware (haswell, skylakex, cooperlake, sapphirerapids, zen) is
  // its own choice for a CPU it knows: kept.
  static const std::array<const char*, 14> kOld = {
      "prescott", "core2",     "penryn", "dunnington", "nehalem",    "atom",        "sandybridge",
      "opteron",  "barcelona", "bobcat", "bulldozer",  "piledriver", "steamroller", "excavator"};
  if (std::find(kOld.begin(), kOld.end(), core) == kOld.end()) return "";
  if (cpu.avx512) return "SkylakeX";
  if (cpu.avx2_fma) return "Haswell";
  return "";
}

std::string blas_corename() {
  using CoreFn = char* (*)();
  if (auto corename = reinterpret_cast<CoreFn>(dlsym(RTLD_DEFAULT, "openblas_get_corename")))
    if (const char* c = corename()) return c;
  return "";
}

void reexec_with_native_blas_kernels(char** argv) {
  if (std::getenv("OPENBLAS_CORETYPE")) return;  // the user's choice, or the second start
  const std::string better = better_blas_coretype(blas_corename(), cpu_vector_units());
  if (better.empty()) return;
  if (setenv("OPENBLAS_CORETYPE", better.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // The exec failed (no /proc): run on with the kernels OpenBLAS picked.
}

}  // namespace stc
