# Unit tests of src/apps/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/apps/test_solve_main.cpp
)
