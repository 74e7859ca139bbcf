# The io stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/io/gmsh_reader.cpp
  src/io/isolated_child.cpp
  src/io/mesh_reader.cpp
  src/io/mesh_validation.cpp
  src/io/surface_readers.cpp
  src/io/surface_tetrahedralize.cpp
  src/io/tetgen_reader.cpp
  src/io/text_cursor.cpp
  src/io/vtk_legacy_reader.cpp
  src/io/vtk_writer.cpp
  src/io/vtu_reader.cpp
)
