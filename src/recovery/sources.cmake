# The recovery stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/recovery/surface_recovery.cpp
)
