# Unit tests of src/gpu/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/gpu/test_gl_cg.cpp
  test/unit/gpu/test_gl_refinement.cpp
  test/unit/gpu/test_gl_scenes.cpp
  test/unit/gpu/test_gl_spmv.cpp
)
