# The gpu stage's sources of tissue_core (explicit: a new file is added here).
list(APPEND TISSUE_CORE_SOURCES
  src/gpu/egl_context.cpp
  src/gpu/gl_cg.cpp
  src/gpu/gl_context_options.cpp
  src/gpu/gl_pass.cpp
  src/gpu/gl_reduction.cpp
  src/gpu/gl_solver.cpp
  src/gpu/gl_spmv.cpp
  src/gpu/gl_texture.cpp
  src/gpu/gl_vector.cpp
  src/gpu/matrix_layout.cpp
  src/gpu/shader_library.cpp
)
