# Unit tests of src/simulation/ (tissue_core_unit; explicit: a new test file is added here).
list(APPEND TISSUE_UNIT_TESTS
  test/unit/simulation/test_hybrid_model.cpp
  test/unit/simulation/test_hybrid_model_livers.cpp
  test/unit/simulation/test_hybrid_model_recovery.cpp
  test/unit/simulation/test_operation_surface.cpp
  test/unit/simulation/test_region_follower.cpp
  test/unit/simulation/test_simulation.cpp
  test/unit/simulation/test_simulation_edge_contact.cpp
  test/unit/simulation/test_simulation_random_cuts.cpp
  test/unit/simulation/test_simulation_replay.cpp
  test/unit/simulation/test_step_times.cpp
  test/unit/simulation/test_surface_snapshot.cpp
)
