# Unit tests of src/recovery/.
list(APPEND TISSUE_UNIT_TESTS
  test/unit/recovery/test_surface_recovery.cpp
)
