# Unit tests of src/generators/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/generators/test_thigh.cpp
)
