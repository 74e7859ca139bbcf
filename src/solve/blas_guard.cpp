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
  settle_openmp_on_this_thread();  // the first caller's thread (below)
  return info;
}

BlasInfo& detected() {
  static BlasInfo info = detect();
  return info;
}

}  // namespace

// CHOLMOD 3 (Debian 12) opens OpenMP regions of a fixed 4 threads (num_threads(4), which
// OMP_NUM_THREADS cannot lower) in every supernodal factorization, to clear work arrays: on
// 2 cores, waking and parking those threads cost more than the work (the thigh's cutting
// step 13.0 -> 6.4 ms, the organ's 44.5 -> 34.3 ms with them off). Inactive parallel regions
// run on the calling thread alone. libgomp keeps that setting per thread (a thread it did not
// start begins from the defaults, one active level): the thread that calls CHOLMOD first sets
// it, and a region move's worker sets it itself (region_follower.cpp; without it the organ
// liver's condensation took 1.0 s instead of 0.55 s). The user may still choose
// (OMP_THREAD_LIMIT, OMP_MAX_ACTIVE_LEVELS).
void settle_openmp_on_this_thread() {
  thread_local bool settled = false;
  if (settled) return;
  settled = true;
  using LevelsFn = void (*)(int);
  static const LevelsFn set =
      std::getenv("OMP_THREAD_LIMIT") || std::getenv("OMP_MAX_ACTIVE_LEVELS")
          ? nullptr
          : reinterpret_cast<LevelsFn>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
  if (set) set(0);
}

namespace {

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
