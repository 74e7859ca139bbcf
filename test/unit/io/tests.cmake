# Unit tests of src/io/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/io/test_gmsh_reader.cpp
  test/unit/io/test_isolated_child.cpp
  test/unit/io/test_mesh_reader.cpp
  test/unit/io/test_mesh_reader_malformed.cpp
)
