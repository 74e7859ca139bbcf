#include "solve/blas_guard.hpp"

#include <dlfcn.h>

#include <atomic>
#include <cstdlib>

namespace stc {
namespace {

// OpenBLAS's own entry points, looked up in the process (CHOLMOD loaded libblas.so.3): absent
// for any other BLAS.
BlasInfo detect() {
  BlasInfo info;
  using ConfigFn = char* (*)();
  using ThreadsFn = void (*)(int);
  if (auto config = reinterpret_cast<ConfigFn>(dlsym(RTLD_DEFAULT, "openblas_get_config")))
    if (const char* c = config()) info.config = c;
  // The single-threaded build: no locks (a build with USE_LOCKING says nothing different in
  // its config, so any single-threaded OpenBLAS is serialized).
  info.serialized = info.config.find("SINGLE_THREADED") != std::string::npos;
  // A threaded OpenBLAS would start a thread per core inside the loop's factorization, beside
  // the worker and the display thread: one, unless the user chose (OPENBLAS_NUM_THREADS).
  if (!info.serialized && !std::getenv("OPENBLAS_NUM_THREADS") && !std::getenv("OMP_NUM_THREADS"))
    if (auto set = reinterpret_cast<ThreadsFn>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
      set(1);
  return info;
}

BlasInfo& detected() {
  static BlasInfo info = detect();
  return info;
}

std::atomic<int> forced{-1};  // -1: as detected, 0: never, 1: always

std::mutex& blas_mutex() {
  static std::mutex m;
  return m;
}

}  // namespace

const BlasInfo& blas_info() { return detected(); }

std::unique_lock<std::mutex> blas_guard() {
  const int f = forced.load();
  const bool serialize = f < 0 ? detected().serialized : f == 1;
  return serialize ? std::unique_lock<std::mutex>(blas_mutex()) : std::unique_lock<std::mutex>();
}

void force_blas_serialization(bool serialize) { forced = serialize ? 1 : 0; }
void reset_blas_serialization() { forced = -1; }

}  // namespace stc
