# The cutting stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/cutting/blade_path.cpp
  src/cutting/closed_marks.cpp
  src/cutting/cut_smoothing.cpp
  src/cutting/cut_state.cpp
  src/cutting/cut_sweep.cpp
  src/cutting/earlier_triangles.cpp
  src/cutting/edge_bisection.cpp
  src/cutting/free_pieces.cpp
  src/cutting/invariants.cpp
  src/cutting/node_moves.cpp
  src/cutting/rest_mapping.cpp
  src/cutting/separation.cpp
  src/cutting/tet_flips.cpp
  src/cutting/tet_grid.cpp
  src/cutting/tip_corner.cpp
  src/cutting/triangle_cut.cpp
  src/cutting/vertex_insertion.cpp
)
