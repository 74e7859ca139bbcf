# The solve stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/solve/backend.cpp
  src/solve/blas_guard.cpp
  src/solve/blas_kernels.cpp
  src/solve/cpu_cg_solver.cpp
  src/solve/framed_cholesky.cpp
  src/solve/held_dof_solve.cpp
  src/solve/interface_last_order.cpp
  src/solve/schur_complement.cpp
  src/solve/sparse_cholesky.cpp
)
