# The assembly stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/assembly/element_cache.cpp
  src/assembly/element_stiffness.cpp
  src/assembly/full_model.cpp
  src/assembly/global_assembly.cpp
  src/assembly/loads.cpp
)
