# Unit tests of src/cutting/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/cutting/test_blade_path.cpp
  test/unit/cutting/test_cut_cases.cpp
  test/unit/cutting/test_cut_fidelity.cpp
  test/unit/cutting/test_cut_fidelity_gravity.cpp
  test/unit/cutting/test_cut_property.cpp
  test/unit/cutting/test_cut_smoothing.cpp
  test/unit/cutting/test_cut_state.cpp
  test/unit/cutting/test_cut_sweep_box.cpp
  test/unit/cutting/test_earlier_triangles.cpp
  test/unit/cutting/test_fidelity_measure.cpp
  test/unit/cutting/test_tet_flips.cpp
  test/unit/cutting/test_tet_grid.cpp
  test/unit/cutting/test_vertex_insertion.cpp
)
