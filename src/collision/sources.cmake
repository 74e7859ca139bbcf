# The collision stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/collision/aabb_tree.cpp
  src/collision/blade.cpp
  src/collision/edge_contact.cpp
  src/collision/surface_bvh.cpp
  src/collision/tet_locator.cpp
  src/collision/tip_contact.cpp
  src/collision/tissue_samples.cpp
)
