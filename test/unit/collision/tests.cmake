# Unit tests of src/collision/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/collision/test_surface_bvh.cpp
  test/unit/collision/test_edge_contact.cpp
)
