# The mesh stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/mesh/boundary_surface.cpp
  src/mesh/face_adjacency.cpp
  src/mesh/quality.cpp
  src/mesh/tet_mesh.cpp
)
