# Unit tests of src/condensation/.
list(APPEND TISSUE_UNIT_TESTS
  test/unit/condensation/test_condensed_part.cpp
)
