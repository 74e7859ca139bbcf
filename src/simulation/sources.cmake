# The simulation stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/simulation/hybrid_model.cpp
  src/simulation/operation_surface.cpp
  src/simulation/region_follower.cpp
  src/simulation/simulation.cpp
  src/simulation/simulation_output.cpp
  src/simulation/step_times.cpp
  src/simulation/surface_snapshot.cpp
)
