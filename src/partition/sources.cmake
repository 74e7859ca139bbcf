# The partition stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/partition/follow_region.cpp
  src/partition/partition.cpp
)
