# Unit tests of src/mesh/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/mesh/test_face_adjacency.cpp
  test/unit/mesh/test_quality.cpp
)
