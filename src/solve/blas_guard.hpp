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
// Either call also keeps the numeric libraries' own threads out of the loop's way (one
// OpenBLAS thread per call, process-wide, at the first; CHOLMOD's OpenMP regions inline, at
// the first on each thread: see blas_guard.cpp).
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

// Tests only: serialize (true), never serialize (false) or detect again (reset).
void force_blas_serialization(bool serialize);
void reset_blas_serialization();

}  // namespace stc
