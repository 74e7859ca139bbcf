# Unit tests of src/solve/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/solve/test_blas_guard.cpp
  test/unit/solve/test_blas_kernels.cpp
  test/unit/solve/test_cpu_cg_preconditioner.cpp
  test/unit/solve/test_cpu_cg_solver.cpp
  test/unit/solve/test_framed_cholesky.cpp
  test/unit/solve/test_held_dof_solve.cpp
  test/unit/solve/test_interface_last_order.cpp
  test/unit/solve/test_schur_complement.cpp
)
