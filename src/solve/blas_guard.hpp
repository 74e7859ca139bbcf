// Thread safety of the BLAS under CHOLMOD (docs/DESIGN.md section 14, "BLAS and threads").
//
// CHOLMOD's supernodal factorization and solve call the BLAS and LAPACK (dsyrk, dgemm, dtrsm,
// dpotrf), and the core calls CHOLMOD from more than one thread: a region move's worker
// condenses while the loop refactors, and the ROS node's display thread recovers u_S while the
// loop solves. Debian 12's libopenblas0-serial is built without locking: two threads in it at
// once share its buffers and get WRONG numbers, silently (a stress test of dsyrk + dpotrf +
// dtrsm from two threads: 1,011 of 40,000 results differ; the follow-region tests saw hybrid
// matrices CG could not solve). `./tissue setup` installs libopenblas0-pthread instead, which
// locks. Whatever BLAS the loader picked, these guards make it safe: when the process runs
// OpenBLAS's single-threaded build, every BLAS-using CHOLMOD call takes one process-wide mutex.
// The first call also keeps the numeric libraries' own threads out of the loop's way (one
// OpenBLAS thread per call; CHOLMOD's OpenMP regions inline on the calling thread: see
// blas_guard.cpp).
#pragma once

#include <mutex>
#include <string>

namespace stc {

// What the loaded BLAS is and whether calls into it are serialized (one line, for the log).
struct BlasInfo {
  std::string config;       // openblas_get_config(), or "" for a BLAS that is not OpenBLAS
  bool serialized = false;  // BLAS-using calls take the process-wide mutex
};
const BlasInfo& blas_info();

// Held around each BLAS-using CHOLMOD call: owns the process-wide mutex when the BLAS is not
// thread-safe, nothing otherwise.
std::unique_lock<std::mutex> blas_guard();

// CHOLMOD's OpenMP regions inline on the calling thread too (libgomp keeps the setting per
// thread): a region move's worker calls it before it condenses. Once per thread; cheap after.
// The loop's and the ROS node's other threads keep what they had: inline there, the thigh
// soak cut ~35 % more steps per minute and its RSS grew past the soak's 64 MB limit
// (docs/DESIGN.md section 14).
void settle_openmp_on_this_thread();

// Tests only: serialize (true), never serialize (false) or detect again (reset).
void force_blas_serialization(bool serialize);
void reset_blas_serialization();

}  // namespace stc
