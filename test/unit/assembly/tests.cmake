# Unit tests of src/assembly/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/assembly/test_element_stiffness.cpp
  test/unit/assembly/test_global_assembly.cpp
  test/unit/assembly/test_full_model_calculix.cpp
)
