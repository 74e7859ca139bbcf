# The generators stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/generators/local_refinement.cpp
  src/generators/structured_tets.cpp
  src/generators/thigh.cpp
)
