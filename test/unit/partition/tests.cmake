# Unit tests of src/partition/.
list(APPEND TISSUE_UNIT_TESTS
  test/unit/partition/test_partition.cpp
)
